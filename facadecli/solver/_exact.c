/* The exact alignment search (facadecli.solver.exact), compiled: branch and bound over the
 * alignment decision network of one candidate, the rules of SPEC 2.4 on every column, the
 * linear equalities a partial path implies and the least squared deviation under them.
 *
 * It follows the Python reference (``exact._Search``) step for step: the same moves in the
 * same order, the same columns, the same bounds, the same children in the same order, the
 * same work units. Sums may be added in another order than numpy adds them (BLAS), so a
 * bound can differ in its last bits; the tests compare the layouts the two find. A complete
 * layout is sized in Python (``leaf``): the search hands it over by its cuts.
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#define FREE 0
#define AFTER_EMPTY 1
#define AFTER_ATTACHED 2
#define LEAF_WORK 20
#define COMBINATION_WORK 64
#define SAME 1e-9

enum { GO = 0, STOP_ERROR = 1, STOP_EXHAUSTED = 2, STOP_PERFECT = 3 };

/* why a column was rejected (formatted in Python) */
enum {
    R_NO_OPAQUE = 1,
    R_ATTACHED_GAP = 2,
    R_NO_COVER = 3,
    R_GAP_BEFORE_ATTACHED = 4,
    R_COVERED = 5,
};

/* -- rows, letters and their moves ---------------------------------------------------- */

typedef struct {
    int var;
    double size; /* NAN: unsized (a placeholder) */
    char transparent, opaque, attached, unoccludable;
    int segment;
} Letter;

typedef struct {
    int start, end;
    double fixed;
    int unsized; /* placeholder letters held whole */
    int letters;
    char lead, opaque, transparent, unoccludable, first_attached, last_attached, fixed_only;
    int piece_of; /* the letter it starts inside, or -1 */
    int tail;     /* the letter whose first piece ends it, or -1 */
    double tail_size;
    double low, high; /* its length at preferred sizes (interval(INF, {})) */
    double *whole;    /* the letters it holds whole, over the variables (lazily) */
} Move;

typedef struct {
    Move *m;
    double *len; /* its length when known, over the variables; NULL for a gap or a piece */
} Option;

typedef struct {
    Option *items;
    int n;
    int fresh; /* lengths computed for one node (inside a split letter): freed with it */
    /* the options by how fitting() checks them: first the entries of whole sized letters
     * (in the options' order, so by least length), then the other ones of known length,
     * then those of unknown length (always allowed) */
    int *order;
    int n_whole, n_known;
} Options;

typedef struct {
    int n; /* letters */
    Letter *letters;
    double least; /* the least preferred size of its sized letters (0: none, or one of 0) */
    int has_attached;
    int *above, n_above;
    int *covering, n_covering;
    Move **moves; /* per position 0 .. 2n: NULL until asked */
    int *n_moves;
    double *counts;   /* (n + 1) x nv: how many of each symbol the first k letters hold */
    double **rem;     /* per position: the sized letters still to lay out whole */
    int **rem_ph;     /* per position: (variable, count) pairs of placeholders, -1 ended */
    Options *cached[2]; /* per position, without and with gaps */
} Row;

typedef struct {
    Row *rows;
    int n;
    int *ends;
} Group;

/* -- the equalities of a partial path --------------------------------------------------- */

typedef struct {
    int refs;
    int npiv, nb;
    int *piv_var;
    double *piv_row; /* npiv x nv */
    double *piv_rhs;
    double *basis; /* nb x sized, orthonormal */
    double *brhs;
    double *point; /* sized */
    double value;
    struct Probes *probes; /* probe() of rows already asked about (lazily) */
} System;

/* probe() results of one system, by the row's bits */
typedef struct Probes {
    double *keys; /* n x nv */
    double *values;
    Py_ssize_t n, cap;
    Py_ssize_t *slots, n_slots;
} Probes;

/* -- the path: columns linked back to the first ----------------------------------------- */

typedef struct Cell {
    int refs;
    struct Cell *prev;
    int depth;
    Move **column; /* one entry a row, NULL for a gap */
} Cell;

typedef struct {
    int *positions, *memory, *before;
    System *system;
    double *x;
    double *used;   /* R x nv */
    char *has_used; /* R */
    Cell *path;
} Node;

typedef struct {
    int code, g, r, a, start, end;
    int progress, count;
} Rejection;

typedef struct {
    PyObject_HEAD
    int nv, sized, G;
    Group *groups;
    double *target;
    double canvas, incumbent;
    int first_only, gaps;
    long long limit, used;
    double deadline;
    int timed_out;
    long long combinations;
    int stop;
    int progress;
    PyObject *leaf;
    Cell **done; /* the path of every finished group */
    Rejection *rej;
    Py_ssize_t n_rej, cap_rej;
    Py_ssize_t *rej_slots, n_rej_slots;
    int recording;
} Search;

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static int spend(Search *s, long long units)
{
    long long before = s->used;
    s->used += units;
    if (s->used > s->limit) {
        s->stop = STOP_EXHAUSTED;
        return -1;
    }
    if (before / 256 != s->used / 256 && isfinite(s->deadline) && now() > s->deadline) {
        s->timed_out = 1;
        s->stop = STOP_EXHAUSTED;
        return -1;
    }
    return 0;
}

static void *alloc(size_t n)
{
    void *p = PyMem_Calloc(n ? n : 1, 1);
    if (!p)
        PyErr_NoMemory();
    return p;
}

static double r9(double x)
{
    if (!isfinite(x))
        return x;
    return nearbyint(x * 1e9) / 1e9;
}

/* -- moves (alignment._Row.moves) ---------------------------------------------------------- */

typedef struct {
    int count, unsized;
    double fixed;
    char opaque, transparent, sized_only, unoccludable, first_attached, last_attached;
} Whole;

static void whole_init(Whole *w)
{
    memset(w, 0, sizeof(*w));
    w->opaque = w->transparent = w->sized_only = 1;
}

static void whole_add(Whole *w, const Letter *l)
{
    if (isnan(l->size)) {
        w->unsized++;
        w->sized_only = 0;
    } else
        w->fixed += l->size;
    if (w->count == 0)
        w->first_attached = l->attached;
    w->last_attached = l->attached;
    w->opaque = w->opaque && l->opaque;
    w->transparent = w->transparent && l->transparent;
    w->unoccludable = w->unoccludable || l->unoccludable;
    w->count++;
}

typedef struct {
    Move *items;
    int n, cap;
} MoveList;

static int push_move(MoveList *list, const Row *row, int start, int end, const Whole *held,
                     int piece_of, int tail)
{
    if (list->n == list->cap) {
        int cap = list->cap ? 2 * list->cap : 16;
        Move *p = PyMem_Realloc(list->items, (size_t)cap * sizeof(Move));
        if (!p) {
            PyErr_NoMemory();
            return -1;
        }
        list->items = p;
        list->cap = cap;
    }
    Move *m = &list->items[list->n++];
    memset(m, 0, sizeof(*m));
    int pieces = (piece_of >= 0) + (tail >= 0);
    m->start = start;
    m->end = end;
    m->fixed = held->fixed;
    m->unsized = held->unsized;
    m->letters = held->count + pieces;
    m->lead = piece_of >= 0 && end != start;
    m->piece_of = piece_of;
    m->tail = tail;
    m->tail_size = tail < 0 ? NAN : (isnan(row->letters[tail].size) ? INFINITY : row->letters[tail].size);
    m->opaque = held->count > 0 && !pieces && held->opaque;
    m->transparent = held->transparent;
    m->unoccludable = held->unoccludable;
    m->first_attached = piece_of < 0 && held->first_attached;
    m->last_attached = tail < 0 && held->last_attached;
    m->fixed_only = piece_of < 0 && tail < 0 && held->sized_only;
    /* interval(INF, {}) */
    if (m->fixed_only) {
        m->low = m->high = m->fixed;
    } else if (start == end) {
        m->low = 0.0;
        m->high = INFINITY;
    } else {
        m->low = m->high = m->fixed;
        if (m->unsized || m->lead)
            m->high = INFINITY;
        if (tail >= 0)
            m->high += m->tail_size;
    }
    return 0;
}

static int extend_moves(MoveList *list, const Row *row, int start, int k, int transparent,
                        int piece_of)
{
    Whole w;
    whole_init(&w);
    if (piece_of >= 0 && push_move(list, row, start, 2 * k, &w, piece_of, -1) < 0)
        return -1;
    int segment = k < row->n ? row->letters[k].segment : 0;
    for (int index = k; index < row->n; index++) {
        const Letter *l = &row->letters[index];
        if (l->transparent != transparent || l->segment != segment)
            return 0;
        whole_add(&w, l);
        if (push_move(list, row, start, 2 * (index + 1), &w, piece_of, -1) < 0)
            return -1;
        int following = index + 1;
        if (transparent && following < row->n && row->letters[following].transparent &&
            push_move(list, row, start, 2 * following + 1, &w, piece_of, following) < 0)
            return -1;
    }
    return 0;
}

static int move_order(const void *pa, const void *pb)
{
    const Move *a = pa, *b = pb;
    if (a->fixed != b->fixed)
        return a->fixed < b->fixed ? -1 : 1;
    if (a->letters != b->letters)
        return a->letters < b->letters ? -1 : 1;
    return (a->end > b->end) - (a->end < b->end);
}

/* the entries out of ``position``, by (least whole length, letters, end) */
static int row_moves(Row *row, int position, Move **out)
{
    if (row->moves[position]) {
        *out = row->moves[position];
        return row->n_moves[position];
    }
    MoveList list = {NULL, 0, 0};
    int k = position / 2, inside = position % 2;
    if (k < row->n) {
        Whole w;
        whole_init(&w);
        if (inside) {
            if (push_move(&list, row, position, position, &w, k, -1) < 0 ||
                extend_moves(&list, row, position, k + 1, 1, k) < 0)
                goto fail;
        } else {
            int transparent = row->letters[k].transparent;
            if (transparent && push_move(&list, row, position, position + 1, &w, -1, k) < 0)
                goto fail;
            if (extend_moves(&list, row, position, k, transparent, -1) < 0)
                goto fail;
        }
    }
    qsort(list.items, (size_t)list.n, sizeof(Move), move_order);
    if (!list.items && !(list.items = alloc(sizeof(Move))))
        return -1;
    row->moves[position] = list.items;
    row->n_moves[position] = list.n;
    *out = list.items;
    return list.n;
fail:
    PyMem_Free(list.items);
    return -1;
}

/* the entry from ``start`` to ``end`` (a middle piece when they are equal), if any */
static Move *spanning(Row *row, int start, int end)
{
    Move *moves;
    int n = row_moves(row, start, &moves);
    for (int i = 0; i < n; i++)
        if (moves[i].end == end && (moves[i].start == moves[i].end) == (start == end))
            return &moves[i];
    return NULL;
}

static double *whole_of(Search *s, Row *row, Move *m)
{
    if (!m->whole) {
        int first = (m->start + 1) / 2, last = m->end / 2;
        if (last < first)
            last = first;
        double *v = alloc(sizeof(double) * (size_t)s->nv);
        if (!v)
            return NULL;
        for (int j = 0; j < s->nv; j++)
            v[j] = row->counts[(size_t)last * s->nv + j] - row->counts[(size_t)first * s->nv + j];
        m->whole = v;
    }
    return m->whole;
}

static int stands_aside(const Move *m)
{
    return m == NULL || m->start == m->end || (m->letters == 1 && m->piece_of < 0 && m->tail >= 0);
}

static int plain(const Move *m)
{
    return m->unsized == 0 && m->piece_of < 0 && m->tail < 0;
}

/* -- the system of equalities ----------------------------------------------------------- */

static System *system_new(Search *s, int npiv, int nb)
{
    size_t nv = (size_t)s->nv, sz = (size_t)s->sized;
    size_t bytes = sizeof(System) + sizeof(int) * (size_t)npiv + sizeof(double) *
                   ((size_t)npiv * nv + (size_t)npiv + (size_t)nb * sz + (size_t)nb + sz) + 16;
    System *y = alloc(bytes);
    if (!y)
        return NULL;
    char *p = (char *)(y + 1);
    p = (char *)(((uintptr_t)p + 7) & ~(uintptr_t)7);
    y->piv_row = (double *)p;
    p += sizeof(double) * (size_t)npiv * nv;
    y->piv_rhs = (double *)p;
    p += sizeof(double) * (size_t)npiv;
    y->basis = (double *)p;
    p += sizeof(double) * (size_t)nb * sz;
    y->brhs = (double *)p;
    p += sizeof(double) * (size_t)nb;
    y->point = (double *)p;
    p += sizeof(double) * sz;
    y->piv_var = (int *)p;
    y->refs = 1;
    y->npiv = npiv;
    y->nb = nb;
    return y;
}

static void system_drop(System *y)
{
    if (y && --y->refs == 0) {
        if (y->probes) {
            PyMem_Free(y->probes->keys);
            PyMem_Free(y->probes->values);
            PyMem_Free(y->probes->slots);
            PyMem_Free(y->probes);
        }
        PyMem_Free(y);
    }
}

/* a hash of 64-bit words (the key of the probe and rejection tables) */
static uint64_t words_hash(const void *key, size_t bytes)
{
    /* each word multiplied on its own (the products pipeline), then mixed (murmur3 fmix) */
    const unsigned char *p = key;
    uint64_t h = 1469598103934665603ULL, k = 0x9E3779B97F4A7C15ULL;
    for (size_t i = 0; i + 8 <= bytes; i += 8) {
        uint64_t b;
        memcpy(&b, p + i, sizeof(b));
        h += (b ^ (b >> 31)) * k;
        k += 0xD6E8FEB86659FD93ULL;
    }
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDULL;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ULL;
    h ^= h >> 33;
    return h;
}

/* where the row's probe is kept (*found: it is there); -1 when out of memory */
static Py_ssize_t probes_slot(Probes *p, const double *row, int nv, int *found)
{
    Py_ssize_t mask = p->n_slots - 1;
    Py_ssize_t j = (Py_ssize_t)(words_hash(row, sizeof(double) * (size_t)nv) & (uint64_t)mask);
    while (p->slots[j]) {
        if (!memcmp(p->keys + (size_t)(p->slots[j] - 1) * nv, row, sizeof(double) * (size_t)nv)) {
            *found = 1;
            return j;
        }
        j = (j + 1) & mask;
    }
    *found = 0;
    return j;
}

static int probes_grow(Probes *p, int nv)
{
    if (p->n == p->cap) {
        Py_ssize_t cap = p->cap ? 2 * p->cap : 64;
        double *keys = PyMem_Realloc(p->keys, sizeof(double) * (size_t)cap * nv);
        if (!keys)
            return -1;
        p->keys = keys;
        double *values = PyMem_Realloc(p->values, sizeof(double) * (size_t)cap);
        if (!values)
            return -1;
        p->values = values;
        p->cap = cap;
    }
    if (2 * (p->n + 1) > p->n_slots) {
        Py_ssize_t n = p->n_slots ? 2 * p->n_slots : 128;
        Py_ssize_t *slots = PyMem_Calloc((size_t)n, sizeof(Py_ssize_t));
        if (!slots)
            return -1;
        PyMem_Free(p->slots);
        p->slots = slots;
        p->n_slots = n;
        for (Py_ssize_t i = 0; i < p->n; i++) {
            int found;
            slots[probes_slot(p, p->keys + (size_t)i * nv, nv, &found)] = i + 1;
        }
    }
    return 0;
}

/* the row with the pivot placeholders solved out (in place) */
static double reduce(const Search *s, const System *y, double *row, double rhs)
{
    for (int i = 0; i < y->npiv; i++) {
        double c = row[y->piv_var[i]];
        if (c != 0.0) {
            const double *pivot = y->piv_row + (size_t)i * s->nv;
            for (int j = 0; j < s->nv; j++)
                row[j] -= c * pivot[j];
            rhs -= c * y->piv_rhs[i];
        }
    }
    return rhs;
}

/* the part of a row over the sized symbols that the basis does not span (in place) */
static double orthogonal(const Search *s, const System *y, double *a, double rhs)
{
    int sz = s->sized;
    if (!y->nb)
        return rhs;
    double c[y->nb];
    for (int round = 0; round < 2; round++) {
        for (int i = 0; i < y->nb; i++) {
            const double *q = y->basis + (size_t)i * sz;
            double t = 0.0;
            for (int j = 0; j < sz; j++)
                t += q[j] * a[j];
            c[i] = t;
        }
        for (int i = 0; i < y->nb; i++) {
            const double *q = y->basis + (size_t)i * sz;
            for (int j = 0; j < sz; j++)
                a[j] -= c[i] * q[j];
            rhs -= c[i] * y->brhs[i];
        }
    }
    return rhs;
}

static double dot(const double *a, const double *b, int n)
{
    double t = 0.0;
    for (int j = 0; j < n; j++)
        t += a[j] * b[j];
    return t;
}

/* the system with ``row @ symbols == rhs`` added: a new reference (y itself when the row
 * adds nothing), NULL with no error set when it conflicts */
static System *system_add(Search *s, System *y, const double *given, double rhs, double scale)
{
    int nv = s->nv, sz = s->sized;
    double row[nv];
    memcpy(row, given, sizeof(double) * (size_t)nv);
    rhs = reduce(s, y, row, rhs);
    int v = -1;
    double most = 1e-9;
    for (int j = sz; j < nv; j++)
        if (fabs(row[j]) > most) {
            most = fabs(row[j]);
            v = j;
        }
    if (v >= 0) {
        System *z = system_new(s, y->npiv + 1, y->nb);
        if (!z)
            return NULL;
        double pv = row[v];
        double *pivot = z->piv_row + (size_t)y->npiv * nv;
        for (int j = 0; j < nv; j++)
            pivot[j] = row[j] / pv;
        double pivot_rhs = rhs / pv;
        for (int i = 0; i < y->npiv; i++) {
            const double *r = y->piv_row + (size_t)i * nv;
            double *out = z->piv_row + (size_t)i * nv;
            z->piv_var[i] = y->piv_var[i];
            double c = r[v];
            if (c != 0.0) {
                for (int j = 0; j < nv; j++)
                    out[j] = r[j] - c * pivot[j];
                z->piv_rhs[i] = y->piv_rhs[i] - c * pivot_rhs;
            } else {
                memcpy(out, r, sizeof(double) * (size_t)nv);
                z->piv_rhs[i] = y->piv_rhs[i];
            }
        }
        z->piv_var[y->npiv] = v;
        z->piv_rhs[y->npiv] = pivot_rhs;
        memcpy(z->basis, y->basis, sizeof(double) * (size_t)y->nb * sz);
        memcpy(z->brhs, y->brhs, sizeof(double) * (size_t)y->nb);
        memcpy(z->point, y->point, sizeof(double) * (size_t)sz);
        z->value = y->value;
        return z;
    }
    rhs = orthogonal(s, y, row, rhs);
    double norm = sqrt(dot(row, row, sz));
    if (norm <= 1e-9) {
        if (fabs(rhs) <= 1e-7 * scale) {
            y->refs++;
            return y;
        }
        return NULL;
    }
    System *z = system_new(s, y->npiv, y->nb + 1);
    if (!z)
        return NULL;
    memcpy(z->piv_var, y->piv_var, sizeof(int) * (size_t)y->npiv);
    memcpy(z->piv_row, y->piv_row, sizeof(double) * (size_t)y->npiv * nv);
    memcpy(z->piv_rhs, y->piv_rhs, sizeof(double) * (size_t)y->npiv);
    memcpy(z->basis, y->basis, sizeof(double) * (size_t)y->nb * sz);
    memcpy(z->brhs, y->brhs, sizeof(double) * (size_t)y->nb);
    double *q = z->basis + (size_t)y->nb * sz;
    for (int j = 0; j < sz; j++)
        q[j] = row[j] / norm;
    z->brhs[y->nb] = rhs / norm;
    double residual = rhs / norm - dot(q, y->point, sz);
    for (int j = 0; j < sz; j++)
        z->point[j] = y->point[j] + residual * q[j];
    z->value = y->value + residual * residual;
    return z;
}

static double probe_of(Search *s, const System *y, const double *given);

/* the bound with ``row @ symbols == 0`` added (INF when it conflicts), kept with the system
 * (a child that adds no equality shares its parent's); NAN when out of memory */
static double probe(Search *s, System *y, const double *given)
{
    int nv = s->nv, found;
    if (!y->probes && !(y->probes = PyMem_Calloc(1, sizeof(Probes))))
        return NAN;
    Probes *p = y->probes;
    if (probes_grow(p, nv) < 0)
        return NAN;
    Py_ssize_t j = probes_slot(p, given, nv, &found);
    if (found)
        return p->values[p->slots[j] - 1];
    double value = probe_of(s, y, given);
    memcpy(p->keys + (size_t)p->n * nv, given, sizeof(double) * (size_t)nv);
    p->values[p->n] = value;
    p->slots[j] = ++p->n;
    return value;
}

static double probe_of(Search *s, const System *y, const double *given)
{
    int nv = s->nv, sz = s->sized;
    double row[nv];
    memcpy(row, given, sizeof(double) * (size_t)nv);
    double rhs = reduce(s, y, row, 0.0);
    for (int j = sz; j < nv; j++)
        if (fabs(row[j]) > 1e-9)
            return y->value;
    rhs = orthogonal(s, y, row, rhs);
    double norm2 = dot(row, row, sz);
    if (norm2 <= 1e-18)
        return fabs(rhs) <= 1e-7 * s->canvas ? y->value : INFINITY;
    double residual = rhs - dot(row, y->point, sz);
    return y->value + residual * residual / norm2;
}

/* -- rejections ----------------------------------------------------------------------------- */

static int reject(Search *s, int code, int g, int r, int a, const Move *m)
{
    if (!s->recording)
        return 0;
    int key[6] = {code, g, r, a, m ? m->start : -1, m ? m->end : -1};
    if (2 * (s->n_rej + 1) > s->n_rej_slots) {
        Py_ssize_t n = s->n_rej_slots ? 2 * s->n_rej_slots : 64;
        Py_ssize_t *slots = PyMem_Calloc((size_t)n, sizeof(Py_ssize_t));
        if (!slots) {
            PyErr_NoMemory();
            s->stop = STOP_ERROR;
            return 0;
        }
        for (Py_ssize_t i = 0; i < s->n_rej; i++) {
            Py_ssize_t j = (Py_ssize_t)(words_hash(&s->rej[i].code, 6 * sizeof(int)) & (uint64_t)(n - 1));
            while (slots[j])
                j = (j + 1) & (n - 1);
            slots[j] = i + 1;
        }
        PyMem_Free(s->rej_slots);
        s->rej_slots = slots;
        s->n_rej_slots = n;
    }
    Py_ssize_t j = (Py_ssize_t)(words_hash(key, sizeof(key)) & (uint64_t)(s->n_rej_slots - 1));
    while (s->rej_slots[j]) {
        Rejection *e = &s->rej[s->rej_slots[j] - 1];
        if (!memcmp(&e->code, key, sizeof(key))) {
            if (s->progress > e->progress)
                e->progress = s->progress;
            e->count++;
            return 0;
        }
        j = (j + 1) & (s->n_rej_slots - 1);
    }
    if (s->n_rej == s->cap_rej) {
        Py_ssize_t cap = s->cap_rej ? 2 * s->cap_rej : 32;
        Rejection *p = PyMem_Realloc(s->rej, (size_t)cap * sizeof(Rejection));
        if (!p) {
            PyErr_NoMemory();
            s->stop = STOP_ERROR;
            return 0;
        }
        s->rej = p;
        s->cap_rej = cap;
    }
    Rejection *e = &s->rej[s->n_rej++];
    memcpy(&e->code, key, sizeof(key));
    e->progress = s->progress;
    e->count = 1;
    s->rej_slots[j] = s->n_rej;
    return 0;
}

/* -- the rules of SPEC 2.4 on one column ------------------------------------------------------ */

static int valid(Search *s, int g, Move **entries, const int *memory)
{
    Group *group = &s->groups[g];
    int first = -1, any_opaque = 0;
    for (int r = 0; r < group->n; r++) {
        if (entries[r]) {
            if (first < 0)
                first = r;
            if (entries[r]->opaque)
                any_opaque = 1;
        }
    }
    if (first < 0)
        return 0;
    if (!any_opaque)
        return reject(s, R_NO_OPAQUE, g, first, -1, entries[first]);
    for (int r = 0; r < group->n; r++) {
        Move *m = entries[r];
        Row *row = &group->rows[r];
        if (!m) {
            if (memory[r] == AFTER_ATTACHED)
                return reject(s, R_ATTACHED_GAP, g, r, -1, NULL);
            int covered = 0;
            for (int i = 0; i < row->n_covering; i++) {
                Move *o = entries[row->covering[i]];
                if (o && o->opaque) {
                    covered = 1;
                    break;
                }
            }
            if (!covered)
                return reject(s, R_NO_COVER, g, r, -1, NULL);
            continue;
        }
        if (m->first_attached && memory[r] == AFTER_EMPTY)
            return reject(s, R_GAP_BEFORE_ATTACHED, g, r, -1, m);
        if (m->unoccludable) {
            for (int i = 0; i < row->n_above; i++) {
                Move *o = entries[row->above[i]];
                if (o && !o->transparent)
                    return reject(s, R_COVERED, g, r, row->above[i], m);
            }
        }
    }
    return 1;
}

/* whether two columns in a row make one valid column (then the path through both is
 * never needed) */
static int merges(Search *s, int g, Move **last, Move **entries, const int *before)
{
    Group *group = &s->groups[g];
    Move *merged[group->n];
    for (int r = 0; r < group->n; r++) {
        Move *a = last[r], *b = entries[r];
        if (!a || !b) {
            if (a != b)
                return 0;
            merged[r] = NULL;
            continue;
        }
        Move *joined = spanning(&group->rows[r], a->start, b->end);
        if (!joined)
            return 0;
        merged[r] = joined;
    }
    int recording = s->recording;
    s->recording = 0;
    int fits = valid(s, g, merged, before);
    s->recording = recording;
    return fits;
}

static Move *stretch_of(Move **entries, int n)
{
    Move *found = NULL;
    for (int r = 0; r < n; r++) {
        Move *m = entries[r];
        if (stands_aside(m))
            continue;
        if (found || !plain(m))
            return NULL;
        found = m;
    }
    return found;
}

static double spread(Move **entries, int n)
{
    double lows = -INFINITY, highs = INFINITY;
    for (int r = 0; r < n; r++) {
        if (entries[r]) {
            if (entries[r]->low > lows)
                lows = entries[r]->low;
            if (entries[r]->high < highs)
                highs = entries[r]->high;
        }
    }
    double d = lows - highs;
    return r9(d > 0.0 ? d : 0.0);
}

/* -- options and columns -------------------------------------------------------------------- */

static double *known_length(Search *s, Row *row, Move *m, const Node *node, int r, int *fresh)
{
    *fresh = 0;
    if (m->tail >= 0 || m->start == m->end)
        return NULL;
    double *w = whole_of(s, row, m);
    if (!w || m->piece_of < 0)
        return w;
    double *v = alloc(sizeof(double) * (size_t)s->nv);
    if (!v)
        return NULL;
    memcpy(v, w, sizeof(double) * (size_t)s->nv);
    v[row->letters[m->start / 2].var] += 1.0;
    const double *used = node->used + (size_t)r * s->nv;
    for (int j = 0; j < s->nv; j++)
        v[j] -= used[j];
    *fresh = 1;
    return v;
}

static void options_free(Options *o)
{
    if (o->fresh)
        for (int i = 0; i < o->n; i++)
            PyMem_Free(o->items[i].len);
    PyMem_Free(o->items);
    PyMem_Free(o->order);
    o->items = NULL;
    o->order = NULL;
}

/* whether a length holds a placeholder */
static int holds_placeholder(const Search *s, const double *len)
{
    for (int k = s->sized; k < s->nv; k++)
        if (len[k] != 0.0)
            return 1;
    return 0;
}

/* o->order: the options sorted into the three kinds fitting() checks apart */
static int options_sort(const Search *s, Options *o)
{
    o->order = alloc(sizeof(int) * (size_t)(o->n + 1));
    if (!o->order)
        return -1;
    int at = 0;
    for (int i = 0; i < o->n; i++) {
        Option *x = &o->items[i];
        if (x->len && plain(x->m) && !holds_placeholder(s, x->len))
            o->order[at++] = i;
    }
    o->n_whole = at;
    for (int i = 0; i < o->n; i++) {
        Option *x = &o->items[i];
        if (x->len && !(plain(x->m) && !holds_placeholder(s, x->len)))
            o->order[at++] = i;
    }
    o->n_known = at - o->n_whole;
    for (int i = 0; i < o->n; i++)
        if (!o->items[i].len)
            o->order[at++] = i;
    return 0;
}

static int options_of(Search *s, int g, int r, const Node *node, Options *out)
{
    Group *group = &s->groups[g];
    Row *row = &group->rows[r];
    int position = node->positions[r];
    int inside = position % 2;
    if (!inside && row->cached[s->gaps][position].items) {
        *out = row->cached[s->gaps][position];
        out->fresh = 0;
        return 0;
    }
    Move *moves = NULL;
    int n = 0, gap = 0;
    if (position < group->ends[r]) {
        n = row_moves(row, position, &moves);
        if (n < 0)
            return -1;
        gap = s->gaps && !inside && row->n_covering;
    } else
        gap = 1;
    Options o = {alloc(sizeof(Option) * (size_t)(n + 1)), 0, 0, NULL, 0, 0};
    if (!o.items)
        return -1;
    for (int i = 0; i < n; i++) {
        int fresh;
        double *len = known_length(s, row, &moves[i], node, r, &fresh);
        if (!len && PyErr_Occurred()) {
            options_free(&o);
            return -1;
        }
        o.fresh |= fresh;
        o.items[o.n++] = (Option){&moves[i], len};
    }
    if (gap)
        o.items[o.n++] = (Option){NULL, NULL};
    if (options_sort(s, &o) < 0) {
        options_free(&o);
        return -1;
    }
    if (!inside) {
        row->cached[s->gaps][position] = o;
        o.fresh = 0;
    }
    *out = o;
    return 0;
}

typedef struct {
    Move **items; /* columns, R entries each */
    int n, cap;
} Columns;

typedef struct {
    Search *s;
    int g, R, last;
    const Node *node;
    Options *opts;
    int *order;
    Move **chosen;
    char ***fits; /* per (first row, option): per row, a fitting mask (both lazily) */
    Columns *out;
} Builder;

static int emit(Builder *b)
{
    Columns *c = b->out;
    if (c->n == c->cap) {
        int cap = c->cap ? 2 * c->cap : 16;
        Move **p = PyMem_Realloc(c->items, sizeof(Move *) * (size_t)cap * b->R);
        if (!p) {
            PyErr_NoMemory();
            return -1;
        }
        c->items = p;
        c->cap = cap;
    }
    memcpy(c->items + (size_t)c->n * b->R, b->chosen, sizeof(Move *) * b->R);
    c->n++;
    return 0;
}

/* what fitting() knows of one first entry while it checks a row's options against it */
typedef struct {
    Search *s;
    System *y;
    const double *first;
    double limit, margin;
    int pinned;       /* the first holds placeholders that the equalities fix ... */
    double *reduced;  /* ... solved out: an entry of sized letters meets (len + reduced) @ sizes */
    double rest;      /* == rest */
} Fit;

/* whether an option of known length ``len`` may be as long as the first: 1 it may, 0 it
 * may not, NOT_NEAR it may not by its own least deviation (the equality alone: see
 * fitting()), with *miss its miss at preferred sizes; -1 out of memory */
#define NOT_NEAR 2
static int fits(const Fit *f, const double *len, double *miss)
{
    Search *s = f->s;
    int nv = s->nv, sz = s->sized, placeholders = 0, own = 0;
    double d[nv], shifted[sz + 1];
    for (int k = 0; k < nv; k++)
        d[k] = len[k] - f->first[k];
    for (int k = sz; k < nv; k++) {
        if (d[k] != 0.0)
            placeholders = 1;
        if (len[k] != 0.0)
            own = 1;
    }
    const double *e = d;
    double alone = 0.0, norm = 0.0, off = 0.0;
    *miss = -1.0;
    if (!placeholders) {
        norm = dot(d, d, sz);
        *miss = dot(d, s->target, sz);
        alone = norm > 0 ? *miss * *miss / norm : 0.0;
    } else if (f->pinned && !own) {
        for (int k = 0; k < sz; k++)
            shifted[k] = len[k] + f->reduced[k];
        e = shifted;
        off = f->rest;
        norm = dot(e, e, sz);
        *miss = dot(e, s->target, sz) - f->rest;
        alone = norm > 0 && *miss * *miss / norm > f->margin ? *miss * *miss / norm : 0.0;
    }
    if (alone > f->limit)
        return norm > 0 && alone > f->margin ? NOT_NEAR : 0;
    if (norm > 0 && (!placeholders || (f->pinned && !own))) {
        /* the bound with the equality: its residual at the system's point is the probe's,
         * over a row no longer than this one (the probe is at least this) */
        double residual = off - dot(e, f->y->point, sz);
        if (f->y->value + residual * residual / norm > f->margin)
            return 0;
    }
    double value = probe(s, f->y, d);
    if (isnan(value)) {
        PyErr_NoMemory();
        return -1;
    }
    return value <= f->limit;
}

/* which options of row r may be as long as the first entry (row fr, option j) within the
 * incumbent: first alone (their preferred lengths apart), then with the equalities.
 *
 * A first entry holding placeholders: with the equalities' pivots solved out of it (when
 * they fix every placeholder it holds), an entry of sized letters must meet
 * (len + reduced) @ sizes == rest; when the least deviation under that equality alone is
 * beyond the limit, so is the probe (it adds the other equalities): no probe then.
 *
 * The entries of whole sized letters out of one position are each the one before and
 * more letters: each letter adds at least the row's least size ``least`` to the miss and
 * at most 1 to the norm. So once one longer than the first is not near, nor are the
 * longer ones; once one shorter is not, nor are the shorter ones (when ``least``^2 is
 * beyond the limit): they are checked outward from the first's length, until both
 * sides stop. */
static char *fitting(Builder *b, int fr, int j, int r)
{
    Search *s = b->s;
    int base = 0;
    for (int q = 0; q < fr; q++)
        base += b->opts[q].n;
    char ***masks = &b->fits[base + j];
    if (!*masks && !(*masks = alloc(sizeof(char *) * (size_t)b->R)))
        return NULL;
    char **slot = &(*masks)[r];
    if (*slot)
        return *slot;
    Options *o = &b->opts[r];
    char *mask = alloc((size_t)o->n + 1);
    if (!mask)
        return NULL;
    int nv = s->nv, sz = s->sized;
    double reduced[nv];
    double limit = s->incumbent + SAME;
    Fit f = {s, b->node->system, b->opts[fr].items[j].len, limit,
             limit + 1e-9 * (1.0 + limit), 0, reduced, 0.0};
    for (int k = sz; k < nv; k++)
        if (f.first[k] != 0.0)
            f.pinned = 1;
    if (f.pinned) {
        for (int k = 0; k < nv; k++)
            reduced[k] = -f.first[k];
        f.rest = reduce(s, f.y, reduced, 0.0);
        for (int k = sz; k < nv; k++)
            if (fabs(reduced[k]) > 1e-9)
                f.pinned = 0;
    }
    double least = s->groups[b->g].rows[r].least;
    int ordered = least * least > f.margin;
    const int *whole = o->order, *known = o->order + o->n_whole;
    const int *unknown = known + o->n_known;
    int nw = o->n_whole, nk = o->n_known, nu = o->n - nw - nk;
    double miss;
    memset(mask, 0, (size_t)o->n + 1);
    for (int u = 0; u < nu; u++)
        mask[unknown[u]] = 1;
    /* with the whole entries first when they are not checked outward */
    for (int pass = ordered; pass < 2; pass++) {
        const int *items = pass ? known : whole;
        int count = pass ? nk : nw;
        for (int w = 0; w < count; w++) {
            int fit = fits(&f, o->items[items[w]].len, &miss);
            if (fit < 0) {
                PyMem_Free(mask);
                return NULL;
            }
            mask[items[w]] = fit == 1;
        }
    }
    if (!ordered) {
        *slot = mask;
        return mask;
    }
    /* the first whole entry at least as long as the first, at preferred sizes */
    double length = f.pinned ? f.rest : 0.0;
    for (int k = 0; k < sz; k++)
        length += (f.pinned ? -reduced[k] : f.first[k]) * s->target[k];
    int low = 0, high = nw; /* binary search: the whole entries are sorted by least length */
    while (low < high) {
        int mid = (low + high) / 2;
        if (o->items[whole[mid]].m->fixed < length)
            low = mid + 1;
        else
            high = mid;
    }
    int start = low;
    for (int w = start; w < nw; w++) { /* longer, outward */
        int fit = fits(&f, o->items[whole[w]].len, &miss);
        if (fit < 0) {
            PyMem_Free(mask);
            return NULL;
        }
        mask[whole[w]] = fit == 1;
        if (fit == NOT_NEAR && miss >= 0)
            break;
    }
    for (int w = start - 1; w >= 0; w--) { /* shorter, outward */
        int fit = fits(&f, o->items[whole[w]].len, &miss);
        if (fit < 0) {
            PyMem_Free(mask);
            return NULL;
        }
        mask[whole[w]] = fit == 1;
        if (fit == NOT_NEAR && miss < 0)
            break;
    }
    *slot = mask;
    return mask;
}

static int extend(Builder *b, int i, int fr, int fj, int solid)
{
    Search *s = b->s;
    s->combinations++;
    if (s->combinations % COMBINATION_WORK == 0 && spend(s, 1) < 0)
        return -1;
    if (i == b->R) {
        if (valid(s, b->g, b->chosen, b->node->memory))
            return s->stop ? -1 : emit(b);
        return s->stop ? -1 : 0;
    }
    int r = b->order[i];
    Options *o = &b->opts[r];
    char *mask = NULL;
    if (fr >= 0 && !(mask = fitting(b, fr, fj, r)))
        return -1;
    for (int k = 0; k < o->n; k++) {
        if (mask && !mask[k])
            continue;
        Move *m = o->items[k].m;
        if (i == b->last && !solid && m && plain(m) && m->letters > 1)
            continue; /* a stretch of several letters: searched a letter at a time */
        b->chosen[r] = m;
        int held = solid || !stands_aside(m);
        int rc;
        if (fr < 0 && o->items[k].len && m)
            rc = extend(b, i + 1, r, k, held);
        else
            rc = extend(b, i + 1, fr, fj, held);
        if (rc < 0)
            return -1;
    }
    b->chosen[r] = NULL;
    return 0;
}

/* every valid column out of a node */
static int columns_of(Search *s, int g, const Node *node, Options *opts, Columns *out)
{
    Group *group = &s->groups[g];
    int R = group->n;
    int order[R];
    Move *chosen[R];
    int total = 0;
    for (int r = 0; r < R; r++) {
        order[r] = r;
        chosen[r] = NULL;
        total += opts[r].n;
    }
    for (int a = 1; a < R; a++) { /* insertion sort: fewest options first, then r */
        int v = order[a], k = a;
        while (k > 0 && opts[order[k - 1]].n > opts[v].n) {
            order[k] = order[k - 1];
            k--;
        }
        order[k] = v;
    }
    char ***fits = alloc(sizeof(char **) * (size_t)total);
    if (!fits)
        return -1;
    Builder b = {s, g, R, R - 1, node, opts, order, chosen, fits, out};
    int rc = extend(&b, 0, -1, -1, 0);
    for (int k = 0; k < total; k++) {
        if (!fits[k])
            continue;
        for (int r = 0; r < R; r++)
            PyMem_Free(fits[k][r]);
        PyMem_Free(fits[k]);
    }
    PyMem_Free(fits);
    return rc;
}

/* -- nodes ------------------------------------------------------------------------------ */

static void cell_drop(Cell *c)
{
    while (c && --c->refs == 0) {
        Cell *prev = c->prev;
        PyMem_Free(c);
        c = prev;
    }
}

static Node *node_new(Search *s, int R)
{
    size_t nv = (size_t)s->nv;
    Node *n = alloc(sizeof(Node));
    if (!n)
        return NULL;
    n->positions = alloc(sizeof(int) * (size_t)R * 3);
    n->x = alloc(sizeof(double) * nv * ((size_t)R + 1));
    n->has_used = alloc((size_t)R);
    if (!n->positions || !n->x || !n->has_used) {
        PyMem_Free(n->positions);
        PyMem_Free(n->x);
        PyMem_Free(n->has_used);
        PyMem_Free(n);
        return NULL;
    }
    n->memory = n->positions + R;
    n->before = n->positions + 2 * R;
    n->used = n->x + nv;
    return n;
}

static void node_free(Node *n)
{
    if (!n)
        return;
    system_drop(n->system);
    cell_drop(n->path);
    PyMem_Free(n->positions);
    PyMem_Free(n->x);
    PyMem_Free(n->has_used);
    PyMem_Free(n);
}

typedef struct {
    double bound, spread;
    long long key; /* the bound to 9 decimals */
    int empties, pieces, letters, index;
    Node *node;
} Child;

static int child_order(const void *pa, const void *pb)
{
    const Child *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    if (a->empties != b->empties)
        return a->empties - b->empties;
    if (a->spread != b->spread)
        return a->spread < b->spread ? -1 : 1;
    if (a->pieces != b->pieces)
        return a->pieces - b->pieces;
    if (a->letters != b->letters)
        return a->letters - b->letters;
    return a->index - b->index;
}

static long long bound_key(double bound)
{
    if (!isfinite(bound) || bound > 9e9)
        return LLONG_MAX;
    return (long long)nearbyint(bound * 1e9);
}

/* the bound strengthened by what each row has laid out and still has to lay out: it must
 * fit the canvas (exact._Search.spans and _System.bound_within) */
static double bound_within(Search *s, int g, const System *y, const double *x,
                           const Node *child)
{
    Group *group = &s->groups[g];
    int sz = s->sized, nv = s->nv, R = group->n;
    /* placeholders fixed by the equalities, and the least a row inside one has used */
    double least[nv - sz > 0 ? nv - sz : 1][sz > 0 ? sz : 1];
    double least_rhs[nv - sz > 0 ? nv - sz : 1];
    char has[nv - sz > 0 ? nv - sz : 1], fixed[nv - sz > 0 ? nv - sz : 1];
    memset(has, 0, sizeof(has));
    memset(fixed, 0, sizeof(fixed));
    for (int i = 0; i < y->npiv; i++) {
        const double *pivot = y->piv_row + (size_t)i * nv;
        int nonzero = 0;
        for (int j = sz; j < nv; j++)
            nonzero += pivot[j] != 0.0;
        if (nonzero == 1) {
            int v = y->piv_var[i] - sz;
            fixed[v] = 1;
            for (int j = 0; j < sz; j++)
                least[v][j] = -pivot[j];
            least_rhs[v] = y->piv_rhs[i];
        }
    }
    double held[nv - sz > 0 ? nv - sz : 1][sz > 0 ? sz : 1];
    for (int r = 0; r < R; r++) {
        if (!child->has_used[r])
            continue;
        const double *amount = child->used + (size_t)r * nv;
        int v = group->rows[r].letters[child->positions[r] / 2].var;
        if (v < sz || fixed[v - sz])
            continue;
        int fine = 1;
        for (int j = sz; j < nv; j++)
            if (amount[j] < -1e-12)
                fine = 0;
        if (!fine)
            continue;
        if (has[v - sz] && !(dot(amount, s->target, sz) > dot(held[v - sz], s->target, sz)))
            continue;
        has[v - sz] = 1;
        memcpy(held[v - sz], amount, sizeof(double) * (size_t)sz);
    }
    for (int v = 0; v < nv - sz; v++) {
        if (fixed[v])
            has[v] = 1;
        else if (has[v]) {
            memcpy(least[v], held[v], sizeof(double) * (size_t)sz);
            least_rhs[v] = 0.0;
        }
    }
    double best = y->value;
    double span[sz > 0 ? sz : 1];
    double a[sz > 0 ? sz : 1];
    double tol = 1e-9 * (s->canvas > 1.0 ? s->canvas : 1.0);
    for (int k = -1; k < R; k++) {
        double most = s->canvas;
        memcpy(span, x, sizeof(double) * (size_t)sz);
        if (k >= 0) {
            Row *row = &group->rows[k];
            int position = child->positions[k];
            const double *rem = row->rem[position];
            for (int j = 0; j < sz; j++)
                span[j] += rem[j];
            for (const int *p = row->rem_ph[position]; *p >= 0; p += 2) {
                int v = p[0] - sz;
                if (has[v]) {
                    for (int j = 0; j < sz; j++)
                        span[j] += p[1] * least[v][j];
                    most -= p[1] * least_rhs[v];
                }
            }
        }
        double violation = dot(span, y->point, sz) - most;
        if (violation <= tol)
            continue;
        memcpy(a, span, sizeof(double) * (size_t)sz);
        if (y->nb) {
            double c[y->nb];
            for (int i = 0; i < y->nb; i++)
                c[i] = dot(y->basis + (size_t)i * sz, span, sz);
            for (int i = 0; i < y->nb; i++)
                for (int j = 0; j < sz; j++)
                    a[j] -= c[i] * y->basis[(size_t)i * sz + j];
        }
        double norm = dot(a, a, sz);
        if (norm <= 1e-12)
            return INFINITY;
        double value = y->value + violation * violation / norm;
        if (value > best)
            best = value;
    }
    return best;
}

/* whether the equalities make ``row @ symbols`` zero */
static int implies_zero(const Search *s, const System *y, const double *given)
{
    int nv = s->nv, sz = s->sized;
    double row[nv];
    memcpy(row, given, sizeof(double) * (size_t)nv);
    double rhs = reduce(s, y, row, 0.0);
    for (int j = sz; j < nv; j++)
        if (fabs(row[j]) > 1e-9)
            return 0;
    rhs = orthogonal(s, y, row, rhs);
    return dot(row, row, sz) <= 1e-18 && fabs(rhs) <= 1e-7 * s->canvas;
}

/* whether an entry ends with the first piece of a split letter that the equalities make
 * empty, after whole letters: the same layout has the letter start in the next column,
 * and that path is searched instead (not when the letter and the next are of two
 * segments: the next column's entries then differ) */
static int empty_piece(const Search *s, const Row *row, const Move *m, const double *used,
                       const System *y)
{
    if (!m || m->tail < 0 || m->start == m->end - 1)
        return 0;
    int k = m->end / 2;
    if (k + 1 < row->n && row->letters[k].segment != row->letters[k + 1].segment)
        return 0;
    return implies_zero(s, y, used);
}

/* the child of a node through a column: NULL when its equalities conflict (no error) */
static Node *child_of(Search *s, int g, const Node *node, Move **entries, int *failed)
{
    Group *group = &s->groups[g];
    int R = group->n, nv = s->nv;
    *failed = 0;
    int wr = -1;
    for (int r = 0; r < R; r++)
        if (entries[r] && entries[r]->piece_of < 0 && entries[r]->tail < 0) {
            wr = r;
            break;
        }
    double *width = whole_of(s, &group->rows[wr], entries[wr]);
    Node *c = node_new(s, R);
    if (!width || !c) {
        *failed = 1;
        node_free(c);
        return NULL;
    }
    memcpy(c->used, node->used, sizeof(double) * (size_t)R * nv);
    memcpy(c->has_used, node->has_used, (size_t)R);
    System *y = node->system;
    y->refs++;
    double known[nv];
    for (int r = 0; r < R && y; r++) {
        Move *m = entries[r];
        if (!m)
            continue;
        double *w = whole_of(s, &group->rows[r], m);
        if (!w) {
            *failed = 1;
            break;
        }
        double *used = c->used + (size_t)r * nv;
        memcpy(known, w, sizeof(double) * (size_t)nv);
        if (m->piece_of >= 0) {
            if (m->start == m->end) {
                for (int j = 0; j < nv; j++)
                    used[j] += width[j];
                continue;
            }
            known[group->rows[r].letters[m->start / 2].var] += 1.0;
            for (int j = 0; j < nv; j++)
                known[j] -= used[j];
            c->has_used[r] = 0;
            memset(used, 0, sizeof(double) * (size_t)nv);
        }
        if (m->tail >= 0) {
            for (int j = 0; j < nv; j++)
                used[j] = width[j] - known[j];
            c->has_used[r] = 1;
        } else if (r != wr) {
            for (int j = 0; j < nv; j++)
                known[j] -= width[j];
            System *z = system_add(s, y, known, 0.0, s->canvas);
            system_drop(y);
            y = z;
            if (!z && PyErr_Occurred())
                *failed = 1;
        }
    }
    for (int r = 0; r < R && y && !*failed; r++)
        if (empty_piece(s, &group->rows[r], entries[r], c->used + (size_t)r * nv, y)) {
            system_drop(y);
            y = NULL;
        }
    if (!y || *failed) {
        system_drop(y);
        node_free(c);
        return NULL;
    }
    c->system = y;
    for (int j = 0; j < nv; j++)
        c->x[j] = node->x[j] + width[j];
    for (int r = 0; r < R; r++) {
        Move *m = entries[r];
        c->positions[r] = m ? m->end : node->positions[r];
        c->before[r] = node->memory[r];
        if (!group->rows[r].has_attached)
            c->memory[r] = FREE;
        else if (!m)
            c->memory[r] = node->memory[r] == AFTER_ATTACHED ? AFTER_ATTACHED : AFTER_EMPTY;
        else
            c->memory[r] = m->last_attached ? AFTER_ATTACHED : FREE;
    }
    return c;
}

static Node *start_of(Search *s, int g, System *y)
{
    int R = s->groups[g].n;
    Node *n = node_new(s, R);
    if (!n)
        return NULL;
    y->refs++;
    n->system = y;
    return n; /* positions 0, memory FREE, x 0, nothing used, no path */
}

static int leaf(Search *s, const Node *node)
{
    if (spend(s, LEAF_WORK) < 0)
        return -1;
    if (!s->leaf) {
        PyErr_SetString(PyExc_RuntimeError, "the search has no leaf() any more");
        s->stop = STOP_ERROR;
        return -1;
    }
    PyObject *paths = PyList_New(s->G);
    if (!paths)
        goto error;
    for (int g = 0; g < s->G; g++) {
        Cell *end = g + 1 < s->G ? s->done[g] : node->path;
        int depth = end ? end->depth : 0, R = s->groups[g].n;
        PyObject *columns = PyList_New(depth);
        if (!columns)
            goto error;
        PyList_SET_ITEM(paths, g, columns);
        for (Cell *c = end; c; c = c->prev) {
            PyObject *column = PyTuple_New(R);
            if (!column)
                goto error;
            PyList_SET_ITEM(columns, c->depth - 1, column);
            for (int r = 0; r < R; r++) {
                PyObject *item;
                if (c->column[r])
                    item = Py_BuildValue("(ii)", c->column[r]->start, c->column[r]->end);
                else {
                    item = Py_None;
                    Py_INCREF(item);
                }
                if (!item)
                    goto error;
                PyTuple_SET_ITEM(column, r, item);
            }
        }
    }
    PyObject *answer = PyObject_CallOneArg(s->leaf, paths);
    Py_DECREF(paths);
    paths = NULL;
    if (!answer)
        goto error;
    double incumbent;
    int stop;
    if (!PyArg_ParseTuple(answer, "dp", &incumbent, &stop)) {
        Py_DECREF(answer);
        goto error;
    }
    Py_DECREF(answer);
    s->incumbent = incumbent;
    if (stop) {
        s->stop = STOP_PERFECT;
        return -1;
    }
    return 0;
error:
    Py_XDECREF(paths);
    s->stop = STOP_ERROR;
    return -1;
}

static int dfs(Search *s, int g, Node *node);

static int finish_group(Search *s, int g, Node *node)
{
    System *closed = system_add(s, node->system, node->x, s->canvas, s->canvas);
    if (!closed && PyErr_Occurred()) {
        s->stop = STOP_ERROR;
        return -1;
    }
    if (spend(s, 1) < 0) {
        system_drop(closed);
        return -1;
    }
    if (!closed || closed->value > s->incumbent + SAME) {
        system_drop(closed);
        return 0;
    }
    int rc;
    if (g + 1 < s->G) {
        s->done[g] = node->path;
        Node *next = start_of(s, g + 1, closed);
        rc = next ? dfs(s, g + 1, next) : (s->stop = STOP_ERROR, -1);
        node_free(next);
    } else
        rc = leaf(s, node);
    system_drop(closed);
    return rc;
}

static int dfs(Search *s, int g, Node *node)
{
    Group *group = &s->groups[g];
    int R = group->n;
    if (!memcmp(node->positions, group->ends, sizeof(int) * (size_t)R))
        return finish_group(s, g, node);
    int progress = 0;
    for (int r = 0; r < R; r++)
        progress += node->positions[r];
    s->progress = progress;
    Options opts[R];
    Columns cols = {NULL, 0, 0};
    Child *children = NULL;
    int n_children = 0, rc = -1;
    int made = 0;
    for (; made < R; made++)
        if (options_of(s, g, made, node, &opts[made]) < 0)
            goto done;
    if (columns_of(s, g, node, opts, &cols) < 0)
        goto done;
    children = alloc(sizeof(Child) * (size_t)(cols.n + 1));
    if (!children)
        goto done;
    for (int k = 0; k < cols.n; k++) {
        Move **entries = cols.items + (size_t)k * R;
        Move *stretch = stretch_of(entries, R);
        if (stretch) {
            if (stretch->letters > 1)
                continue;
        } else if (node->path && merges(s, g, node->path->column, entries, node->before))
            continue;
        if (spend(s, 1) < 0)
            goto done;
        int failed;
        Node *c = child_of(s, g, node, entries, &failed);
        if (failed) {
            s->stop = STOP_ERROR;
            goto done;
        }
        if (!c)
            continue;
        double bound = bound_within(s, g, c->system, c->x, c);
        if (bound > s->incumbent + SAME) {
            node_free(c);
            continue;
        }
        Cell *cell = alloc(sizeof(Cell) + sizeof(Move *) * (size_t)R);
        if (!cell) {
            node_free(c);
            s->stop = STOP_ERROR;
            goto done;
        }
        cell->refs = 1;
        cell->prev = node->path;
        if (node->path)
            node->path->refs++;
        cell->depth = node->path ? node->path->depth + 1 : 1;
        cell->column = (Move **)(cell + 1);
        memcpy(cell->column, entries, sizeof(Move *) * (size_t)R);
        c->path = cell;
        Child *ch = &children[n_children];
        ch->bound = bound;
        ch->key = bound_key(bound);
        ch->empties = ch->pieces = ch->letters = 0;
        for (int r = 0; r < R; r++) {
            Move *m = entries[r];
            if (!m) {
                ch->empties++;
                continue;
            }
            ch->pieces += (m->piece_of >= 0) + (m->tail >= 0);
            ch->letters += m->letters;
        }
        ch->spread = spread(entries, R);
        ch->index = n_children;
        ch->node = c;
        n_children++;
    }
    PyMem_Free(cols.items);
    cols.items = NULL;
    for (int r = 0; r < R; r++)
        if (opts[r].fresh)
            options_free(&opts[r]);
    made = 0;
    qsort(children, (size_t)n_children, sizeof(Child), child_order);
    rc = 0;
    for (int k = 0; k < n_children; k++) {
        if (r9(children[k].bound) > s->incumbent + SAME)
            break;
        if (dfs(s, g, children[k].node) < 0) {
            rc = -1;
            break;
        }
        node_free(children[k].node);
        children[k].node = NULL;
    }
done:
    for (int k = 0; k < n_children; k++)
        node_free(children[k].node);
    PyMem_Free(children);
    PyMem_Free(cols.items);
    for (int r = 0; r < made; r++)
        if (opts[r].fresh)
            options_free(&opts[r]);
    if (rc < 0 && !s->stop)
        s->stop = STOP_ERROR;
    return rc;
}

/* -- the Python type ------------------------------------------------------------------------ */

static void free_groups(Search *s)
{
    if (!s->groups)
        return;
    for (int g = 0; g < s->G; g++) {
        Group *group = &s->groups[g];
        for (int r = 0; r < group->n && group->rows; r++) {
            Row *row = &group->rows[r];
            int positions = 2 * row->n + 1;
            if (row->moves) {
                for (int p = 0; p < positions; p++) {
                    if (!row->moves[p])
                        continue;
                    for (int i = 0; i < row->n_moves[p]; i++)
                        PyMem_Free(row->moves[p][i].whole);
                    PyMem_Free(row->moves[p]);
                }
            }
            for (int gaps = 0; gaps < 2; gaps++)
                if (row->cached[gaps])
                    for (int p = 0; p < positions; p++) {
                        PyMem_Free(row->cached[gaps][p].items);
                        PyMem_Free(row->cached[gaps][p].order);
                    }
            if (row->rem)
                PyMem_Free(row->rem[0]); /* the block of every position's */
            if (row->rem_ph)
                PyMem_Free(row->rem_ph[0]);
            PyMem_Free(row->rem);
            PyMem_Free(row->rem_ph);
            PyMem_Free(row->cached[0]);
            PyMem_Free(row->cached[1]);
            PyMem_Free(row->moves);
            PyMem_Free(row->n_moves);
            PyMem_Free(row->counts);
            PyMem_Free(row->letters);
            PyMem_Free(row->above);
            PyMem_Free(row->covering);
        }
        PyMem_Free(group->rows);
        PyMem_Free(group->ends);
    }
    PyMem_Free(s->groups);
    s->groups = NULL;
}

static int Search_traverse(Search *s, visitproc visit, void *arg)
{
    Py_VISIT(s->leaf);
    return 0;
}

static int Search_clear(Search *s)
{
    Py_CLEAR(s->leaf);
    return 0;
}

static void Search_dealloc(Search *s)
{
    PyObject_GC_UnTrack(s);
    free_groups(s);
    PyMem_Free(s->target);
    PyMem_Free(s->done);
    PyMem_Free(s->rej);
    PyMem_Free(s->rej_slots);
    Py_CLEAR(s->leaf);
    Py_TYPE(s)->tp_free((PyObject *)s);
}

static int int_list(PyObject *seq, int **out, int *n, int bound)
{
    PyObject *fast = PySequence_Fast(seq, "a list of row indices");
    if (!fast)
        return -1;
    *n = (int)PySequence_Fast_GET_SIZE(fast);
    *out = alloc(sizeof(int) * (size_t)(*n + 1));
    if (!*out) {
        Py_DECREF(fast);
        return -1;
    }
    for (int i = 0; i < *n; i++) {
        long v = PyLong_AsLong(PySequence_Fast_GET_ITEM(fast, i));
        if (v == -1 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return -1;
        }
        if (v < 0 || v >= bound) {
            Py_DECREF(fast);
            PyErr_SetString(PyExc_ValueError, "a row index out of range");
            return -1;
        }
        (*out)[i] = (int)v;
    }
    Py_DECREF(fast);
    return 0;
}

/* a row from (letters, above, covering); letters: (symbol, size or None, transparent, opaque,
 * attached, unoccludable, segment), the symbol numbered by ``variables`` */
static int read_row(Search *s, Row *row, PyObject *spec, int R, PyObject *variables)
{
    PyObject *letters, *above, *covering;
    if (!PyArg_ParseTuple(spec, "OOO", &letters, &above, &covering))
        return -1;
    PyObject *fast = PySequence_Fast(letters, "a row's letters");
    if (!fast)
        return -1;
    int n = row->n = (int)PySequence_Fast_GET_SIZE(fast);
    int nv = s->nv, positions = 2 * n + 1;
    row->letters = alloc(sizeof(Letter) * (size_t)(n + 1));
    row->counts = alloc(sizeof(double) * (size_t)(n + 1) * nv);
    row->moves = alloc(sizeof(Move *) * (size_t)positions);
    row->n_moves = alloc(sizeof(int) * (size_t)positions);
    row->cached[0] = alloc(sizeof(Options) * (size_t)positions);
    row->cached[1] = alloc(sizeof(Options) * (size_t)positions);
    row->rem = alloc(sizeof(double *) * (size_t)positions);
    row->rem_ph = alloc(sizeof(int *) * (size_t)positions);
    if (!row->letters || !row->counts || !row->moves || !row->n_moves || !row->cached[0] ||
        !row->cached[1] || !row->rem || !row->rem_ph) {
        Py_DECREF(fast);
        return -1;
    }
    int sized = 0; /* sized letters met */
    for (int k = 0; k < n; k++) {
        PyObject *symbol, *size, *var;
        Letter *l = &row->letters[k];
        int t, o, a, u;
        PyObject *item = PySequence_Fast_GET_ITEM(fast, k);
        if (!PyTuple_Check(item) || PyTuple_GET_SIZE(item) != 7) {
            Py_DECREF(fast);
            PyErr_SetString(PyExc_TypeError, "a letter is a tuple of 7 items");
            return -1;
        }
        symbol = PyTuple_GET_ITEM(item, 0);
        size = PyTuple_GET_ITEM(item, 1);
        t = PyObject_IsTrue(PyTuple_GET_ITEM(item, 2));
        o = PyObject_IsTrue(PyTuple_GET_ITEM(item, 3));
        a = PyObject_IsTrue(PyTuple_GET_ITEM(item, 4));
        u = PyObject_IsTrue(PyTuple_GET_ITEM(item, 5));
        l->segment = (int)PyLong_AsLong(PyTuple_GET_ITEM(item, 6));
        if (t < 0 || o < 0 || a < 0 || u < 0 || (l->segment == -1 && PyErr_Occurred())) {
            Py_DECREF(fast);
            return -1;
        }
        var = PyDict_GetItemWithError(variables, symbol);
        l->var = var ? (int)PyLong_AsLong(var) : -1;
        if (l->var < 0 || l->var >= nv) {
            Py_DECREF(fast);
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_ValueError, "a letter's symbol is not a variable");
            return -1;
        }
        l->size = size == Py_None ? NAN : PyFloat_AsDouble(size);
        if (l->size == -1.0 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return -1;
        }
        if (!isnan(l->size)) {
            double size = l->size > 0 ? l->size : 0.0;
            if (!sized++ || size < row->least)
                row->least = size;
        }
        l->transparent = (char)t;
        l->opaque = (char)o;
        l->attached = (char)a;
        l->unoccludable = (char)u;
        row->has_attached |= a;
        memcpy(row->counts + (size_t)(k + 1) * nv, row->counts + (size_t)k * nv,
               sizeof(double) * (size_t)nv);
        row->counts[(size_t)(k + 1) * nv + l->var] += 1.0;
    }
    Py_DECREF(fast);
    /* what is left to lay out whole from each position (one block each for all of them) */
    size_t rem_size = (size_t)(s->sized + 1), ph_size = (size_t)(2 * (nv - s->sized) + 1);
    double *rem_block = alloc(sizeof(double) * rem_size * (size_t)positions);
    int *ph_block = alloc(sizeof(int) * ph_size * (size_t)positions);
    if (!rem_block || !ph_block) {
        PyMem_Free(rem_block);
        PyMem_Free(ph_block);
        return -1;
    }
    for (int p = 0; p < positions; p++) {
        double *rem = row->rem[p] = rem_block + rem_size * (size_t)p;
        int *ph = row->rem_ph[p] = ph_block + ph_size * (size_t)p;
        const double *all = row->counts + (size_t)n * nv;
        const double *before = row->counts + (size_t)((p + 1) / 2) * nv;
        int m = 0;
        for (int v = s->sized; v < nv; v++) {
            int count = (int)(all[v] - before[v]);
            if (count) {
                ph[m++] = v;
                ph[m++] = count;
            }
        }
        ph[m] = -1;
        for (int v = 0; v < s->sized; v++)
            rem[v] = all[v] - before[v];
    }
    if (int_list(above, &row->above, &row->n_above, R) < 0 ||
        int_list(covering, &row->covering, &row->n_covering, R) < 0)
        return -1;
    return 0;
}

static int Search_init(Search *s, PyObject *args, PyObject *kwds)
{
    static char *names[] = {"groups", "variables", "target", "canvas", "incumbent", "limit",
                            "used", "deadline", "first_only", "leaf", NULL};
    PyObject *groups, *variables, *target, *leaf;
    int first_only;
    double canvas, incumbent, deadline;
    long long limit, used;
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "OO!OddLLdpO", names, &groups, &PyDict_Type,
                                     &variables, &target, &canvas, &incumbent, &limit, &used,
                                     &deadline, &first_only, &leaf))
        return -1;
    int nv = (int)PyDict_GET_SIZE(variables);
    if (!PyCallable_Check(leaf)) {
        PyErr_SetString(PyExc_TypeError, "leaf must be callable");
        return -1;
    }
    free_groups(s);
    Py_INCREF(leaf);
    Py_XSETREF(s->leaf, leaf);
    PyObject *tfast = PySequence_Fast(target, "the preferred sizes");
    if (!tfast)
        return -1;
    s->nv = nv;
    s->sized = (int)PySequence_Fast_GET_SIZE(tfast);
    if (s->sized > nv) {
        Py_DECREF(tfast);
        PyErr_SetString(PyExc_ValueError, "more sized symbols than variables");
        return -1;
    }
    PyMem_Free(s->target);
    s->target = alloc(sizeof(double) * (size_t)(s->sized + 1));
    if (!s->target) {
        Py_DECREF(tfast);
        return -1;
    }
    for (int j = 0; j < s->sized; j++) {
        s->target[j] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(tfast, j));
        if (s->target[j] == -1.0 && PyErr_Occurred()) {
            Py_DECREF(tfast);
            return -1;
        }
    }
    Py_DECREF(tfast);
    s->canvas = canvas;
    s->incumbent = incumbent;
    s->limit = limit;
    s->used = used;
    s->deadline = deadline;
    s->first_only = first_only;
    PyObject *gfast = PySequence_Fast(groups, "the groups");
    if (!gfast)
        return -1;
    s->G = (int)PySequence_Fast_GET_SIZE(gfast);
    s->groups = alloc(sizeof(Group) * (size_t)(s->G + 1));
    PyMem_Free(s->done);
    s->done = alloc(sizeof(Cell *) * (size_t)(s->G + 1));
    if (!s->groups || !s->done) {
        Py_DECREF(gfast);
        return -1;
    }
    for (int g = 0; g < s->G; g++) {
        PyObject *rows = PySequence_Fast(PySequence_Fast_GET_ITEM(gfast, g), "a group's rows");
        if (!rows) {
            Py_DECREF(gfast);
            return -1;
        }
        Group *group = &s->groups[g];
        int R = (int)PySequence_Fast_GET_SIZE(rows);
        group->rows = alloc(sizeof(Row) * (size_t)(R + 1));
        group->ends = alloc(sizeof(int) * (size_t)(R + 1));
        if (!group->rows || !group->ends) {
            Py_DECREF(rows);
            Py_DECREF(gfast);
            return -1;
        }
        group->n = R;
        for (int r = 0; r < R; r++) {
            if (read_row(s, &group->rows[r], PySequence_Fast_GET_ITEM(rows, r), R, variables) < 0) {
                group->n = r + 1;
                Py_DECREF(rows);
                Py_DECREF(gfast);
                return -1;
            }
            group->ends[r] = 2 * group->rows[r].n;
        }
        Py_DECREF(rows);
    }
    Py_DECREF(gfast);
    return 0;
}

/* a row without gaps has letters that fill the canvas, whatever the alignment */
static System *filling(Search *s, System *y)
{
    double total[s->nv];
    for (int g = 0; g < s->G && y; g++) {
        Group *group = &s->groups[g];
        for (int r = 0; r < group->n && y; r++) {
            Row *row = &group->rows[r];
            if (s->gaps && row->n_covering)
                continue;
            memcpy(total, row->counts + (size_t)row->n * s->nv, sizeof(double) * (size_t)s->nv);
            System *z = system_add(s, y, total, s->canvas, s->canvas);
            system_drop(y);
            y = z;
        }
    }
    return y;
}

static PyObject *Search_run(Search *s, PyObject *args)
{
    int gaps;
    if (!PyArg_ParseTuple(args, "p", &gaps))
        return NULL;
    s->gaps = gaps;
    s->stop = GO;
    s->recording = 1;
    if (s->G == 0) {
        PyErr_SetString(PyExc_ValueError, "a search needs a group of rows");
        return NULL;
    }
    System *empty = system_new(s, 0, 0);
    if (!empty)
        return NULL;
    memcpy(empty->point, s->target, sizeof(double) * (size_t)s->sized);
    System *y = filling(s, empty);
    if (!y) {
        if (PyErr_Occurred())
            return NULL;
        return PyLong_FromLong(GO);
    }
    Node *start = start_of(s, 0, y);
    system_drop(y);
    if (!start)
        return NULL;
    dfs(s, 0, start);
    node_free(start);
    if (s->stop == STOP_ERROR) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_MemoryError, "the exact search ran out of memory");
        return NULL;
    }
    return PyLong_FromLong(s->stop);
}

static PyObject *Search_rejections(Search *s, PyObject *unused)
{
    PyObject *out = PyList_New(s->n_rej);
    if (!out)
        return NULL;
    for (Py_ssize_t i = 0; i < s->n_rej; i++) {
        Rejection *e = &s->rej[i];
        PyObject *t = Py_BuildValue("(iiiiiiii)", e->code, e->g, e->r, e->a, e->start, e->end,
                                    e->progress, e->count);
        if (!t) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, i, t);
    }
    return out;
}

static PyObject *Search_get_used(Search *s, void *c) { return PyLong_FromLongLong(s->used); }
static PyObject *Search_get_timed_out(Search *s, void *c) { return PyBool_FromLong(s->timed_out); }
static PyObject *Search_get_incumbent(Search *s, void *c) { return PyFloat_FromDouble(s->incumbent); }

static PyGetSetDef Search_getset[] = {
    {"used", (getter)Search_get_used, NULL, "work units spent, the budget's count included", NULL},
    {"timed_out", (getter)Search_get_timed_out, NULL, "the deadline fired", NULL},
    {"incumbent", (getter)Search_get_incumbent, NULL, "the objective to beat", NULL},
    {NULL},
};

static PyMethodDef Search_methods[] = {
    {"run", (PyCFunction)Search_run, METH_VARARGS,
     "run(gaps) -> 0 done, 2 budget exhausted, 3 stopped by leaf()"},
    {"rejections", (PyCFunction)Search_rejections, METH_NOARGS,
     "(code, group, row, other row, start, end, progress, count) of every rejection"},
    {NULL},
};

static PyTypeObject SearchType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "facadecli.solver._exact.Search",
    .tp_basicsize = sizeof(Search),
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC, /* leaf() may hold the search */
    .tp_traverse = (traverseproc)Search_traverse,
    .tp_clear = (inquiry)Search_clear,
    .tp_doc = "The exact search of one candidate's groups (see facadecli.solver.exact).",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Search_init,
    .tp_dealloc = (destructor)Search_dealloc,
    .tp_methods = Search_methods,
    .tp_getset = Search_getset,
};

/* -- the sizing's elimination (sizing._parametrized, compiled) -------------------------- */

typedef struct {
    int *v;
    double *c;
    int n, cap;
} Sparse; /* (variable, coefficient) pairs, in the order they came */

static int sparse_push(Sparse *e, int v, double c)
{
    if (e->n == e->cap) {
        int cap = e->cap ? 2 * e->cap : 4;
        int *vs = PyMem_Realloc(e->v, sizeof(int) * (size_t)cap);
        if (!vs)
            return -1;
        e->v = vs;
        double *cs = PyMem_Realloc(e->c, sizeof(double) * (size_t)cap);
        if (!cs)
            return -1;
        e->c = cs;
        e->cap = cap;
    }
    e->v[e->n] = v;
    e->c[e->n] = c;
    e->n++;
    return 0;
}

typedef struct {
    int n;
    Sparse *expr;  /* per solved variable: its expression in the free ones */
    double *konst; /* ... and its constant */
    char *solved;
    Sparse *users; /* per variable: solved variables whose expression named it (maybe no more) */
    double *acc;   /* scratch, one per variable */
    int *at;       /* scratch: where a variable is in the expression being changed, or -1 */
} Elimination;

static void elimination_free(Elimination *el)
{
    for (int v = 0; v < el->n; v++) {
        if (el->expr) {
            PyMem_Free(el->expr[v].v);
            PyMem_Free(el->expr[v].c);
        }
        if (el->users) {
            PyMem_Free(el->users[v].v);
            PyMem_Free(el->users[v].c);
        }
    }
    PyMem_Free(el->expr);
    PyMem_Free(el->users);
    PyMem_Free(el->konst);
    PyMem_Free(el->solved);
    PyMem_Free(el->acc);
    PyMem_Free(el->at);
}

typedef struct {
    Py_ssize_t index, length;
} RowOrder;

static int row_order(const void *a, const void *b)
{
    const RowOrder *x = a, *y = b;
    if (x->length != y->length)
        return x->length < y->length ? -1 : 1;
    return x->index < y->index ? -1 : x->index > y->index;
}

/* substitute pivot p = expr + konst into the expression of solved variable v */
static int substitute(Elimination *el, int v, int p, double zero)
{
    Sparse *e = &el->expr[v];
    const Sparse *x = &el->expr[p];
    int k = -1;
    for (int i = 0; i < e->n; i++)
        if (e->v[i] == p) {
            k = i;
            break;
        }
    if (k < 0)
        return 0; /* named it once, not any more */
    double c = e->c[k];
    e->n--; /* p out, the last in its place */
    e->v[k] = e->v[e->n];
    e->c[k] = e->c[e->n];
    for (int i = 0; i < e->n; i++)
        el->at[e->v[i]] = i;
    for (int i = 0; i < x->n; i++) {
        int u = x->v[i];
        double value = c * x->c[i];
        int j = el->at[u];
        if (j >= 0) {
            value += e->c[j];
            e->c[j] = value;
        } else {
            if (sparse_push(e, u, value) < 0)
                return -1;
            el->at[u] = e->n - 1;
            if (sparse_push(&el->users[u], v, 0.0) < 0)
                return -1;
        }
    }
    int kept = 0; /* drop what cancelled */
    for (int i = 0; i < e->n; i++) {
        el->at[e->v[i]] = -1;
        if (fabs(e->c[i]) > zero) {
            e->v[kept] = e->v[i];
            e->c[kept] = e->c[i];
            kept++;
        }
    }
    e->n = kept;
    el->konst[v] += c * el->konst[p];
    return 0;
}

static PyObject *eliminate(PyObject *self, PyObject *args)
{
    PyObject *rows;
    int n;
    double zero, tolerance;
    if (!PyArg_ParseTuple(args, "Oidd", &rows, &n, &zero, &tolerance))
        return NULL;
    PyObject *seq = PySequence_Fast(rows, "rows must be a sequence");
    if (!seq)
        return NULL;
    Py_ssize_t m = PySequence_Fast_GET_SIZE(seq);
    Elimination el = {.n = n};
    RowOrder *order = PyMem_Calloc((size_t)m + 1, sizeof(RowOrder));
    int *touched = PyMem_Calloc((size_t)n + 1, sizeof(int));
    PyObject *result = NULL;
    el.expr = PyMem_Calloc((size_t)n + 1, sizeof(Sparse));
    el.users = PyMem_Calloc((size_t)n + 1, sizeof(Sparse));
    el.konst = PyMem_Calloc((size_t)n + 1, sizeof(double));
    el.solved = PyMem_Calloc((size_t)n + 1, 1);
    el.acc = PyMem_Calloc((size_t)n + 1, sizeof(double));
    el.at = PyMem_Malloc(sizeof(int) * ((size_t)n + 1));
    if (!order || !touched || !el.expr || !el.users || !el.konst || !el.solved || !el.acc ||
        !el.at) {
        PyErr_NoMemory();
        goto done;
    }
    for (int v = 0; v < n; v++)
        el.at[v] = -1;
    for (Py_ssize_t i = 0; i < m; i++) {
        PyObject *row = PySequence_Fast_GET_ITEM(seq, i);
        PyObject *coefficients;
        double rhs;
        if (!PyArg_ParseTuple(row, "Od", &coefficients, &rhs))
            goto done;
        if (!PyDict_Check(coefficients)) {
            PyErr_SetString(PyExc_TypeError, "a row's coefficients must be a dict");
            goto done;
        }
        order[i].index = i;
        order[i].length = PyDict_Size(coefficients);
    }
    qsort(order, (size_t)m, sizeof(RowOrder), row_order); /* shortest first, stable */
    for (Py_ssize_t i = 0; i < m; i++) {
        PyObject *row = PySequence_Fast_GET_ITEM(seq, order[i].index);
        PyObject *coefficients = PyTuple_GET_ITEM(row, 0);
        double left = PyFloat_AsDouble(PyTuple_GET_ITEM(row, 1));
        if (left == -1.0 && PyErr_Occurred())
            goto done;
        int count = 0;
        Py_ssize_t pos = 0;
        PyObject *key, *value;
        while (PyDict_Next(coefficients, &pos, &key, &value)) {
            long v = PyLong_AsLong(key);
            double c = PyFloat_AsDouble(value);
            if (PyErr_Occurred())
                goto done;
            if (v < 0 || v >= n) {
                PyErr_SetString(PyExc_IndexError, "a row names a variable out of range");
                goto done;
            }
            if (el.solved[v]) {
                left -= c * el.konst[v];
                const Sparse *e = &el.expr[v];
                for (int j = 0; j < e->n; j++) {
                    int u = e->v[j];
                    if (el.at[u] < 0) {
                        el.at[u] = count;
                        touched[count++] = u;
                        el.acc[u] = 0.0;
                    }
                    el.acc[u] += c * e->c[j];
                }
            } else {
                if (el.at[v] < 0) {
                    el.at[v] = count;
                    touched[count++] = (int)v;
                    el.acc[v] = 0.0;
                }
                el.acc[v] += c;
            }
        }
        int pivot = -1, terms = 0;
        double best = 0.0;
        for (int j = 0; j < count; j++) {
            int u = touched[j];
            el.at[u] = -1;
            if (fabs(el.acc[u]) <= zero)
                continue;
            touched[terms++] = u;
            double size = fabs(el.acc[u]);
            if (pivot < 0 || size > best || (size == best && u > pivot)) {
                pivot = u;
                best = size;
            }
        }
        if (pivot < 0) {
            if (fabs(left) > tolerance) {
                Py_INCREF(Py_None);
                result = Py_None; /* the equalities contradict each other */
                goto done;
            }
            continue;
        }
        double a = el.acc[pivot];
        Sparse *x = &el.expr[pivot];
        for (int j = 0; j < terms; j++) {
            int u = touched[j];
            if (u != pivot && sparse_push(x, u, -el.acc[u] / a) < 0) {
                PyErr_NoMemory();
                goto done;
            }
        }
        el.konst[pivot] = left / a;
        Sparse *named = &el.users[pivot];
        for (int j = 0; j < named->n; j++)
            if (substitute(&el, named->v[j], pivot, zero) < 0) {
                PyErr_NoMemory();
                goto done;
            }
        named->n = 0;
        el.solved[pivot] = 1;
        for (int j = 0; j < x->n; j++)
            if (sparse_push(&el.users[x->v[j]], pivot, 0.0) < 0) {
                PyErr_NoMemory();
                goto done;
            }
    }
    {
        /* (constants, free variables, (variable, free index, coefficient) of the rest) */
        PyObject *constants = PyList_New(n), *free = PyList_New(0), *entries = PyList_New(0);
        result = PyTuple_Pack(3, constants, free, entries);
        Py_XDECREF(constants);
        Py_XDECREF(free);
        Py_XDECREF(entries);
        if (!result)
            goto done;
        int columns = 0;
        for (int v = 0; v < n; v++) {
            el.at[v] = el.solved[v] ? -1 : columns++;
            PyObject *k = PyFloat_FromDouble(el.solved[v] ? el.konst[v] : 0.0);
            if (!k)
                goto fail;
            PyList_SET_ITEM(constants, v, k);
            if (!el.solved[v]) {
                PyObject *index = PyLong_FromLong(v);
                if (!index || PyList_Append(free, index) < 0) {
                    Py_XDECREF(index);
                    goto fail;
                }
                Py_DECREF(index);
            }
        }
        for (int v = 0; v < n; v++) {
            const Sparse *e = &el.expr[v];
            for (int j = 0; el.solved[v] && j < e->n; j++) {
                PyObject *t = Py_BuildValue("(iid)", v, el.at[e->v[j]], e->c[j]);
                if (!t || PyList_Append(entries, t) < 0) {
                    Py_XDECREF(t);
                    goto fail;
                }
                Py_DECREF(t);
            }
        }
        goto done;
    fail:
        Py_CLEAR(result);
    }
done:
    PyMem_Free(order);
    PyMem_Free(touched);
    elimination_free(&el);
    Py_DECREF(seq);
    return result;
}

static PyMethodDef module_methods[] = {
    {"eliminate", eliminate, METH_VARARGS,
     "eliminate(rows, n, zero, tolerance): every solution of the sparse equalities rows "
     "((coefficients by variable, rhs) pairs) over n variables, as (constants, free "
     "variables, (variable, free index, coefficient) triples); None when they contradict "
     "each other"},
    {NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT,
    .m_name = "_exact",
    .m_doc = "The exact alignment search, compiled; and the sizing's elimination.",
    .m_size = -1,
    .m_methods = module_methods,
};

PyMODINIT_FUNC PyInit__exact(void)
{
    if (PyType_Ready(&SearchType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
    Py_INCREF(&SearchType);
    if (PyModule_AddObject(m, "Search", (PyObject *)&SearchType) < 0) {
        Py_DECREF(&SearchType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
