/* The grammar search (facadecli.grammar.search), compiled: the actions offered for each region
 * of the tiling, building grammars region by region (greedy, or ADP's explore-or-exploit
 * choice), the merged cost of a grammar and the value table it teaches.
 *
 * It computes exactly what the Python reference does (``Search._make_actions`` for the
 * actions, tests/adp_reference.py for the loop), to the bit: the same Mersenne Twister
 * draws as ``random.Random`` (its state is handed over), the same sums in the same order, the
 * same tie rules. Only the speed differs. The tests compare the two.
 *
 * Ids: an *entry* is a region to split (its heap key and content); an *action* is one rule
 * an entry may take; a *content* is what regions read (``Grid.content``: numbered here on
 * their own). An action's parts are written as symbols: a content for a non-terminal,
 * -1 - label for a terminal.
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

/* -- growable arrays ------------------------------------------------------------------ */

static int grow(void **data, Py_ssize_t *cap, Py_ssize_t need, size_t item)
{
    if (need <= *cap)
        return 0;
    Py_ssize_t cap2 = *cap ? *cap : 16;
    while (cap2 < need)
        cap2 *= 2;
    void *p = PyMem_Realloc(*data, (size_t)cap2 * item);
    if (!p) {
        PyErr_NoMemory();
        return -1;
    }
    *data = p;
    *cap = cap2;
    return 0;
}

#define GROW(arr, cap, need) grow((void **)&(arr), &(cap), (need), sizeof(*(arr)))

/* -- sets of int sequences (rule kinds, grammars seen) -------------------------------- */

typedef struct {
    int *pool;           /* each sequence: its length, then its items */
    Py_ssize_t pool_n, pool_cap;
    Py_ssize_t *at;      /* where sequence i starts in the pool */
    Py_ssize_t n, at_cap;
    Py_ssize_t *slots;   /* open addressing: index + 1, or 0 */
    Py_ssize_t n_slots;  /* a power of two */
} SeqSet;

static uint64_t seq_hash(const int *v, int n)
{
    uint64_t h = 1469598103934665603ULL ^ (uint64_t)n;
    for (int i = 0; i < n; i++) {
        h ^= (uint32_t)v[i];
        h *= 1099511628211ULL;
        h ^= h >> 29;
    }
    return h;
}

static int seqset_rehash(SeqSet *s, Py_ssize_t n_slots)
{
    Py_ssize_t *slots = PyMem_Calloc((size_t)n_slots, sizeof(Py_ssize_t));
    if (!slots) {
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i < s->n; i++) {
        const int *seq = s->pool + s->at[i];
        Py_ssize_t j = (Py_ssize_t)(seq_hash(seq + 1, seq[0]) & (uint64_t)(n_slots - 1));
        while (slots[j])
            j = (j + 1) & (n_slots - 1);
        slots[j] = i + 1;
    }
    PyMem_Free(s->slots);
    s->slots = slots;
    s->n_slots = n_slots;
    return 0;
}

/* The index of the sequence, added if new (``*added`` says so); -1 on error. */
static Py_ssize_t seqset_add(SeqSet *s, const int *v, int n, int *added)
{
    if (!s->n_slots && seqset_rehash(s, 1024) < 0)
        return -1;
    uint64_t h = seq_hash(v, n);
    Py_ssize_t j = (Py_ssize_t)(h & (uint64_t)(s->n_slots - 1));
    while (s->slots[j]) {
        const int *seq = s->pool + s->at[s->slots[j] - 1];
        if (seq[0] == n && !memcmp(seq + 1, v, (size_t)n * sizeof(int))) {
            *added = 0;
            return s->slots[j] - 1;
        }
        j = (j + 1) & (s->n_slots - 1);
    }
    if (GROW(s->pool, s->pool_cap, s->pool_n + n + 1) < 0 || GROW(s->at, s->at_cap, s->n + 1) < 0)
        return -1;
    s->at[s->n] = s->pool_n;
    s->pool[s->pool_n] = n;
    memcpy(s->pool + s->pool_n + 1, v, (size_t)n * sizeof(int));
    s->pool_n += n + 1;
    s->slots[j] = ++s->n;
    *added = 1;
    if (2 * s->n > s->n_slots && seqset_rehash(s, 2 * s->n_slots) < 0)
        return -1;
    return s->n - 1;
}

static void seqset_free(SeqSet *s)
{
    PyMem_Free(s->pool);
    PyMem_Free(s->at);
    PyMem_Free(s->slots);
    memset(s, 0, sizeof(*s));
}

/* -- Python's random.random(): MT19937 and genrand_res53, from random.getstate() ------- */

#define MT_N 624
#define MT_M 397

typedef struct {
    uint32_t state[MT_N];
    int index;
} Twister;

static uint32_t mt_next(Twister *t)
{
    static const uint32_t mag01[2] = {0x0U, 0x9908b0dfU};
    uint32_t y, *mt = t->state;
    if (t->index >= MT_N) {
        int k;
        for (k = 0; k < MT_N - MT_M; k++) {
            y = (mt[k] & 0x80000000U) | (mt[k + 1] & 0x7fffffffU);
            mt[k] = mt[k + MT_M] ^ (y >> 1) ^ mag01[y & 0x1U];
        }
        for (; k < MT_N - 1; k++) {
            y = (mt[k] & 0x80000000U) | (mt[k + 1] & 0x7fffffffU);
            mt[k] = mt[k + (MT_M - MT_N)] ^ (y >> 1) ^ mag01[y & 0x1U];
        }
        y = (mt[MT_N - 1] & 0x80000000U) | (mt[0] & 0x7fffffffU);
        mt[MT_N - 1] = mt[MT_M - 1] ^ (y >> 1) ^ mag01[y & 0x1U];
        t->index = 0;
    }
    y = mt[t->index++];
    y ^= (y >> 11);
    y ^= (y << 7) & 0x9d2c5680U;
    y ^= (y << 15) & 0xefc60000U;
    y ^= (y >> 18);
    return y;
}

static double mt_random(Twister *t)
{
    uint32_t a = mt_next(t) >> 5, b = mt_next(t) >> 6;
    return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
}

/* -- the tiling's regions and the actions offered for them ---------------------------------
 *
 * What ``Search._make_actions`` (search.py) computes, to the bit: the lines that may cut a
 * region, the heuristic's cost of each line (Eq. 5), the cuts that keep periodic runs and
 * repeated regions whole, the cuts in two the heuristic likes best, a gridsplit with the
 * extension, each written as the cheapest rule that fits its parts. Python's version stays
 * the reference (the tests compare the two) and makes the chosen rules' ``Action``s.
 * Contents are numbered here on their own; they equal Python's where Python's are equal. */

enum { EXT_ABA = 1, EXT_SYMSPLIT = 2, EXT_GRIDSPLIT = 4 };
enum { OP_SPLIT, OP_REPEAT, OP_ABA, OP_SYMSPLIT, OP_GRID };
#define TOP_ACTIONS 8
#define GRID_CELLS 48

typedef struct {
    int rows, cols;
    int32_t *labels;   /* rows x cols, bottom row first */
    double *xs, *ys;   /* the cuts: cols + 1, rows + 1 */
    double qx, qy;     /* the size quantum along each axis */
    int32_t *change_x, *cross_x; /* (rows + 1) x (cols - 1): counts up to each row */
    int32_t *change_y, *cross_y; /* (rows - 1) x (cols + 1): counts up to each column */
    int n_repeats;
    int32_t *repeats;  /* r0, r1, c0, c1, cells per occurrence, by first row */
    int ext;
    double split_cost, repeat_cost;
    SeqSet keys;       /* content keys -> content */
    int *terminal;     /* per content: its label, or -1 */
    Py_ssize_t terminal_cap;
    SeqSet regions;    /* (r0, r1, c0, c1) -> index */
    int *region_cid;
    Py_ssize_t region_cap;
    SeqSet forms;      /* (op, axis, count, centre, sizes...) -> form */
    int *buffer;       /* scratch for keys */
    Py_ssize_t buffer_cap;
    long long cells_read, cells_max; /* the contents' budget (``regions.WORK_MAX``, less ``Grid.charge``) */
    int spent;         /* a content was refused: the budget ran out */
} Grid;

static PyObject *BudgetError; /* regions.BudgetError's compiled twin */

static void grid_free(Grid *g)
{
    PyMem_Free(g->labels);
    PyMem_Free(g->xs);
    PyMem_Free(g->ys);
    PyMem_Free(g->change_x);
    PyMem_Free(g->cross_x);
    PyMem_Free(g->change_y);
    PyMem_Free(g->cross_y);
    PyMem_Free(g->repeats);
    PyMem_Free(g->terminal);
    PyMem_Free(g->region_cid);
    PyMem_Free(g->buffer);
    seqset_free(&g->keys);
    seqset_free(&g->regions);
    seqset_free(&g->forms);
    memset(g, 0, sizeof(*g));
}

/* The prefix counts of ``regions.Grid``: for x lines, per line between columns c - 1 and c,
 * label changes (and element crossings) in the rows below each row; for y the same across. */
static int grid_prefixes(Grid *g, int background)
{
    int R = g->rows, C = g->cols;
    size_t nx = (size_t)(R + 1) * (size_t)(C > 1 ? C - 1 : 0);
    size_t ny = (size_t)(R > 1 ? R - 1 : 0) * (size_t)(C + 1);
    g->change_x = PyMem_Calloc(nx + 1, sizeof(int32_t));
    g->cross_x = PyMem_Calloc(nx + 1, sizeof(int32_t));
    g->change_y = PyMem_Calloc(ny + 1, sizeof(int32_t));
    g->cross_y = PyMem_Calloc(ny + 1, sizeof(int32_t));
    if (!g->change_x || !g->cross_x || !g->change_y || !g->cross_y) {
        PyErr_NoMemory();
        return -1;
    }
    const int32_t *L = g->labels;
    for (int r = 0; r < R; r++)
        for (int c = 1; c < C; c++) {
            int same = L[r * C + c] == L[r * C + c - 1];
            size_t at = (size_t)(r + 1) * (C - 1) + (c - 1), below = (size_t)r * (C - 1) + (c - 1);
            g->change_x[at] = g->change_x[below] + !same;
            g->cross_x[at] = g->cross_x[below] + (same && L[r * C + c] != background);
        }
    for (int r = 1; r < R; r++)
        for (int c = 0; c < C; c++) {
            int same = L[r * C + c] == L[(r - 1) * C + c];
            size_t at = (size_t)(r - 1) * (C + 1) + c + 1, left = (size_t)(r - 1) * (C + 1) + c;
            g->change_y[at] = g->change_y[left] + !same;
            g->cross_y[at] = g->cross_y[left] + (same && L[r * C + c] != background);
        }
    return 0;
}

#define CHX(g, r, i) ((g)->change_x[(size_t)(r) * ((g)->cols - 1) + (i)])
#define CRX(g, r, i) ((g)->cross_x[(size_t)(r) * ((g)->cols - 1) + (i)])
#define CHY(g, i, c) ((g)->change_y[(size_t)(i) * ((g)->cols + 1) + (c)])
#define CRY(g, i, c) ((g)->cross_y[(size_t)(i) * ((g)->cols + 1) + (c)])

static int buffer_room(Grid *g, Py_ssize_t n) { return GROW(g->buffer, g->buffer_cap, n); }

/* ``Grid.content``: the region's content, numbered as met; -1 on error. */
static int grid_content(Grid *g, int r0, int r1, int c0, int c1)
{
    int box[4] = {r0, r1, c0, c1}, added;
    Py_ssize_t at = seqset_add(&g->regions, box, 4, &added);
    if (at < 0)
        return -1;
    if (!added)
        return g->region_cid[at];
    int nr = 0, nc = 0, w = c1 - c0, h = r1 - r0;
    if (g->spent) {
        PyErr_SetString(BudgetError, "the contents' budget has run out");
        return -1;
    }
    if (buffer_room(g, 2 + (Py_ssize_t)w * h + 2 * (w + h) + 4) < 0)
        return -1;
    /* starts of merged columns and rows, kept at the end of the buffer */
    int *starts_c = g->buffer + g->buffer_cap - (w + h + 2), *starts_r = starts_c + w + 1;
    for (int j = 0; j < w; j++)
        if (j == 0 || CHX(g, r1, c0 + j - 1) != CHX(g, r0, c0 + j - 1))
            starts_c[nc++] = j;
    for (int i = 0; i < h; i++)
        if (i == 0 || CHY(g, r0 + i - 1, c1) != CHY(g, r0 + i - 1, c0))
            starts_r[nr++] = i;
    starts_c[nc] = w;
    starts_r[nr] = h;
    /* what the key reads and keeps: counted first, so the budget bounds memory and time */
    long long cost = 2 + (long long)nr * nc + nr + nc;
    if (g->cells_read + cost > g->cells_max) {
        g->spent = 1;
        PyErr_SetString(BudgetError, "the contents' budget has run out");
        return -1;
    }
    g->cells_read += cost;
    int *key = g->buffer, n = 0;
    key[n++] = nr;
    key[n++] = nc;
    for (int i = 0; i < nr; i++)
        for (int j = 0; j < nc; j++)
            key[n++] = g->labels[(size_t)(r0 + starts_r[i]) * g->cols + c0 + starts_c[j]];
    for (int j = 0; j < nc; j++)
        key[n++] = (int)nearbyint((g->xs[c0 + starts_c[j + 1]] - g->xs[c0 + starts_c[j]]) / g->qx);
    for (int i = 0; i < nr; i++)
        key[n++] = (int)nearbyint((g->ys[r0 + starts_r[i + 1]] - g->ys[r0 + starts_r[i]]) / g->qy);
    Py_ssize_t cid = seqset_add(&g->keys, key, n, &added);
    if (cid < 0)
        return -1;
    if (added) {
        if (GROW(g->terminal, g->terminal_cap, cid + 1) < 0)
            return -1;
        g->terminal[cid] = nr * nc == 1 ? key[2] : -1;
    }
    if (GROW(g->region_cid, g->region_cap, at + 1) < 0)
        return -1;
    g->region_cid[at] = (int)cid;
    return (int)cid;
}

static long grid_quantum(const Grid *g, int axis, int a, int b)
{
    return axis == 0 ? (long)nearbyint((g->xs[b] - g->xs[a]) / g->qx)
                     : (long)nearbyint((g->ys[b] - g->ys[a]) / g->qy);
}

/* An action before it is kept: its rank, and its parts as regions (offsets in the pool of
 * its region's drafts, which may move as it grows). */
typedef struct {
    double heuristic, cost;
    int axis; /* 0: x, 1: y (a gridsplit ranks as y) */
    int op, count, centre;
    Py_ssize_t bounds, across, written, cids; /* offsets in Drafts.pool */
    int n_bounds, n_across, n_written;
    int order; /* where it stood before the last sort: ties keep it */
} Draft;

typedef struct {
    Draft *items;
    Py_ssize_t n, cap;
    int *pool;
    Py_ssize_t pool_n, pool_cap;
} Drafts;

#define DP(d, off) ((d)->pool + (off))

static Py_ssize_t drafts_alloc(Drafts *d, Py_ssize_t n)
{
    if (GROW(d->pool, d->pool_cap, d->pool_n + n + 1) < 0)
        return -1;
    d->pool_n += n;
    return d->pool_n - n;
}

static int compare_bounds(const int *a, int na, const int *b, int nb)
{
    for (int i = 0; i < na && i < nb; i++)
        if (a[i] != b[i])
            return a[i] < b[i] ? -1 : 1;
    return (na > nb) - (na < nb);
}

/* ``Rank``: heuristic, cost, axis, bounds, least first. */
typedef struct {
    double heuristic, cost;
    int axis;
    const int *bounds;
    int n_bounds;
} Rank;

static int compare_ranks(const Rank *a, const Rank *b)
{
    if (a->heuristic != b->heuristic)
        return a->heuristic < b->heuristic ? -1 : 1;
    if (a->cost != b->cost)
        return a->cost < b->cost ? -1 : 1;
    if (a->axis != b->axis)
        return a->axis < b->axis ? -1 : 1;
    return compare_bounds(a->bounds, a->n_bounds, b->bounds, b->n_bounds);
}

/* ``Rank``, then the order before the sort. */
static int compare_drafts(const Drafts *d, const Draft *a, const Draft *b)
{
    Rank x = {a->heuristic, a->cost, a->axis, DP(d, a->bounds), a->n_bounds};
    Rank y = {b->heuristic, b->cost, b->axis, DP(d, b->bounds), b->n_bounds};
    int c = compare_ranks(&x, &y);
    if (c)
        return c;
    return (a->order > b->order) - (a->order < b->order);
}

/* A stable sort of drafts[lo:hi] by rank (insertion: a region has a few dozen at most). */
static void sort_drafts(Drafts *d, Py_ssize_t lo, Py_ssize_t hi)
{
    for (Py_ssize_t i = lo; i < hi; i++)
        d->items[i].order = (int)i;
    for (Py_ssize_t i = lo + 1; i < hi; i++) {
        Draft x = d->items[i];
        Py_ssize_t j = i;
        while (j > lo && compare_drafts(d, &x, &d->items[j - 1]) < 0) {
            d->items[j] = d->items[j - 1];
            j--;
        }
        d->items[j] = x;
    }
}

typedef struct {
    int r0, r1, c0, c1;
    double *cost[2]; /* per axis, the heuristic's cost of each line, indexed from lo */
    int lo[2];
    int *inside;     /* the repeated regions' occurrences inside the region */
    int n_inside;
} Place;

static double line_cost(const Place *p, int axis, int line)
{
    return p->cost[axis][line - p->lo[axis]];
}

static void part_of(const Place *p, int axis, int a, int b, int *out)
{
    if (axis == 0) {
        out[0] = p->r0, out[1] = p->r1, out[2] = a, out[3] = b;
    } else {
        out[0] = a, out[1] = b, out[2] = p->c0, out[3] = p->c1;
    }
}

/* Eq. 5's sum over the lines a rule cuts, as Python's sum() adds them. */
static double lines_cost(const Place *p, int axis, const int *bounds, int n_bounds)
{
    double s = 0.0;
    for (int i = 1; i < n_bounds - 1; i++)
        s += line_cost(p, axis, bounds[i]);
    return s;
}

/* ``Search._action``: the cheapest rule over the parts between the bounds, as a draft;
 * 0 (none when fewer than two parts: d->n unchanged), or -1 on error. */
static int draft_action(Grid *g, const Place *p, Drafts *d, int axis, const int *bounds_in,
                        int n_bounds)
{
    int n = n_bounds - 1;
    if (n < 2)
        return 0;
    Py_ssize_t bounds = drafts_alloc(d, n_bounds), parts = drafts_alloc(d, 4 * n),
               cids = drafts_alloc(d, n);
    if (bounds < 0 || parts < 0 || cids < 0)
        return -1;
    memcpy(DP(d, bounds), bounds_in, (size_t)n_bounds * sizeof(int));
    for (int i = 0; i < n; i++) {
        part_of(p, axis, bounds_in[i], bounds_in[i + 1], DP(d, parts) + 4 * i);
        const int *q = DP(d, parts) + 4 * i;
        int cid = grid_content(g, q[0], q[1], q[2], q[3]);
        if (cid < 0)
            return -1;
        DP(d, cids)[i] = cid;
    }
    const int *c = DP(d, cids);
    int op = OP_SPLIT, m = n, count = 1, centre = 0, period = 0;
    for (int q = 1; q <= n / 2 && !period; q++) {
        if (n % q)
            continue;
        int same = 1;
        for (int i = q; i < n && same; i++)
            same = c[i] == c[i - q];
        if (same)
            period = q;
    }
    if (period) {
        op = OP_REPEAT, m = period, count = n / period;
    } else if ((g->ext & EXT_ABA) && n >= 5 && n % 2 == 1) {
        int same = 1;
        for (int i = 2; i < n && same; i++)
            same = c[i] == c[i - 2];
        if (same)
            op = OP_ABA, m = 2, count = n / 2;
    }
    if (op == OP_SPLIT && (g->ext & EXT_SYMSPLIT) && n >= 3) {
        int same = 1;
        for (int i = 0; i < n && same; i++)
            same = c[i] == c[n - 1 - i];
        if (same)
            op = OP_SYMSPLIT, m = (n + 1) / 2, centre = n % 2 == 1;
    }
    if (GROW(d->items, d->cap, d->n + 1) < 0)
        return -1;
    Draft *a = &d->items[d->n++];
    a->cost = ((op == OP_REPEAT || op == OP_ABA) ? g->repeat_cost : g->split_cost) + m;
    a->heuristic = a->cost + lines_cost(p, axis, bounds_in, n_bounds);
    a->axis = axis, a->op = op, a->count = count, a->centre = centre;
    a->bounds = bounds, a->n_bounds = n_bounds;
    a->across = 0, a->n_across = 0;
    a->written = parts, a->n_written = m;
    a->cids = cids;
    return 0;
}

/* ``Search._gridsplit``: rows by the usable y lines, columns by the usable x lines. */
static int draft_grid(Grid *g, const Place *p, Drafts *d, const int *ys, int ny, const int *xs,
                      int nx)
{
    int rows = ny + 1, cols = nx + 1, n = rows * cols;
    Py_ssize_t bounds = drafts_alloc(d, rows + 1), across = drafts_alloc(d, cols + 1),
               parts = drafts_alloc(d, 4 * n), cids = drafts_alloc(d, n);
    if (bounds < 0 || across < 0 || parts < 0 || cids < 0)
        return -1;
    int *b = DP(d, bounds), *x = DP(d, across);
    b[0] = p->r0, b[rows] = p->r1, x[0] = p->c0, x[cols] = p->c1;
    memcpy(b + 1, ys, (size_t)ny * sizeof(int));
    memcpy(x + 1, xs, (size_t)nx * sizeof(int));
    for (int i = 0; i < rows; i++)
        for (int j = 0; j < cols; j++) {
            int *q = DP(d, parts) + 4 * (i * cols + j);
            q[0] = DP(d, bounds)[i], q[1] = DP(d, bounds)[i + 1];
            q[2] = DP(d, across)[j], q[3] = DP(d, across)[j + 1];
            int cid = grid_content(g, q[0], q[1], q[2], q[3]);
            if (cid < 0)
                return -1;
            DP(d, cids)[i * cols + j] = cid;
        }
    if (GROW(d->items, d->cap, d->n + 1) < 0)
        return -1;
    Draft *a = &d->items[d->n++];
    a->cost = g->split_cost + n;
    a->heuristic = a->cost + lines_cost(p, 0, DP(d, across), cols + 1);
    a->heuristic += lines_cost(p, 1, DP(d, bounds), rows + 1);
    a->axis = 1, a->op = OP_GRID, a->count = 1, a->centre = 0;
    a->bounds = bounds, a->n_bounds = rows + 1;
    a->across = across, a->n_across = cols + 1;
    a->written = parts, a->n_written = n;
    a->cids = cids;
    return 0;
}

static int has_draft(const Drafts *d, Py_ssize_t lo, int axis, const int *bounds, int n_bounds)
{
    for (Py_ssize_t i = lo; i < d->n; i++) {
        const Draft *a = &d->items[i];
        if (a->op != OP_GRID && a->axis == axis &&
            !compare_bounds(DP(d, a->bounds), a->n_bounds, bounds, n_bounds))
            return 1;
    }
    return 0;
}

/* ``Search._line_costs`` of one axis into p->cost[axis] (zero where not positive). */
static int place_line_costs(const Grid *g, Place *p, int axis)
{
    int lo = axis == 0 ? p->c0 : p->r0, hi = axis == 0 ? p->c1 : p->r1, size = hi - lo + 1;
    double *cost = PyMem_Calloc((size_t)size + 1, sizeof(double));
    if (!cost) {
        PyErr_NoMemory();
        return -1;
    }
    p->cost[axis] = cost, p->lo[axis] = lo;
    if (p->n_inside == 0 || hi - lo < 2)
        return 0;
    double *pos = PyMem_Calloc((size_t)size, sizeof(double));
    double *neg = PyMem_Calloc((size_t)size, sizeof(double));
    if (!pos || !neg) {
        PyMem_Free(pos);
        PyMem_Free(neg);
        PyErr_NoMemory();
        return -1;
    }
    for (int k = 0; k < p->n_inside; k++) {
        const int32_t *rep = g->repeats + 5 * p->inside[k];
        int start = axis == 0 ? rep[2] : rep[0], stop = axis == 0 ? rep[3] : rep[1];
        pos[start + 1 - lo] += (double)rep[4];
        neg[stop - lo] += (double)rep[4];
    }
    double cells = (double)(p->r1 - p->r0) * (double)(p->c1 - p->c0), sum = 0.0;
    for (int i = 0; i < size; i++) {
        sum += pos[i] - neg[i];
        if (i >= 1 && i < hi - lo) {
            double c = sum / cells;
            cost[i] = c > 0 ? c : 0.0; /* cost[line - lo] */
        }
    }
    PyMem_Free(pos);
    PyMem_Free(neg);
    return 0;
}

/* ``Search._runs``: bounds keeping each maximal periodic run of parts as one part. */
static int add_runs(Grid *g, const Place *p, Drafts *d, Py_ssize_t found, int axis,
                    const int *full, int n_full, int *work)
{
    int n = n_full - 1;
    int *cids = work, *run = work + n, *out = work + 2 * n + 1;
    for (int i = 0; i < n; i++) {
        int q[4];
        part_of(p, axis, full[i], full[i + 1], q);
        if ((cids[i] = grid_content(g, q[0], q[1], q[2], q[3])) < 0)
            return -1;
    }
    for (int period = 1; period <= n / 2; period++) {
        run[n - period] = 0;
        for (int j = n - period - 1; j >= 0; j--)
            run[j] = cids[j] == cids[j + period] ? run[j + 1] + 1 : 0;
        int i = 0;
        while (i + 2 * period <= n) {
            int k = 1 + run[i] / period;
            if (k >= 2 && !(i == 0 && i + k * period == n)) {
                int end = i + k * period, m = 0;
                for (int j = 0; j <= i; j++)
                    out[m++] = full[j];
                for (int j = end; j <= n; j++)
                    out[m++] = full[j];
                if (!has_draft(d, found, axis, out, m) && draft_action(g, p, d, axis, out, m) < 0)
                    return -1;
                i = end;
            } else {
                i++;
            }
        }
    }
    return 0;
}

static int compare_spans(const void *x, const void *y)
{
    const int *a = x, *b = y;
    int la = a[0] - a[1], lb = b[0] - b[1];
    if (la != lb)
        return la < lb ? -1 : 1;
    if (a[0] != b[0])
        return a[0] < b[0] ? -1 : 1;
    return (a[1] > b[1]) - (a[1] < b[1]);
}

/* ``Search._repeated``: bounds keeping whole the repeated regions across the region. */
static int add_repeated(Grid *g, const Place *p, Drafts *d, Py_ssize_t found, int axis,
                        const int *full, int n_full, int *work)
{
    int *spans = work, n = 0;
    for (int k = 0; k < p->n_inside; k++) {
        const int32_t *rep = g->repeats + 5 * p->inside[k];
        if (axis == 0 && rep[0] == p->r0 && rep[1] == p->r1)
            spans[2 * n] = rep[2], spans[2 * n + 1] = rep[3], n++;
        else if (axis == 1 && rep[2] == p->c0 && rep[3] == p->c1)
            spans[2 * n] = rep[0], spans[2 * n + 1] = rep[1], n++;
    }
    if (!n)
        return 0;
    qsort(spans, (size_t)n, 2 * sizeof(int), compare_spans);
    int lo = full[0], hi = full[n_full - 1];
    int *blocks = spans + 2 * n, nb = 0;
    for (int i = 0; i < n; i++) {
        int a = spans[2 * i], b = spans[2 * i + 1], free_ = !(a == lo && b == hi);
        for (int j = 0; j < nb && free_; j++)
            free_ = b <= blocks[2 * j] || blocks[2 * j + 1] <= a;
        if (free_)
            blocks[2 * nb] = a, blocks[2 * nb + 1] = b, nb++;
    }
    if (!nb)
        return 0;
    /* lo, hi, the blocks' ends, and the lines inside no block: sorted, once each */
    int *marks = blocks + 2 * nb, span = hi - lo + 1, m = 0;
    int *out = marks + span;
    memset(marks, 0, (size_t)span * sizeof(int));
    marks[0] = marks[span - 1] = 1;
    for (int j = 0; j < nb; j++)
        marks[blocks[2 * j] - lo] = marks[blocks[2 * j + 1] - lo] = 1;
    for (int i = 0; i < n_full; i++) {
        int line = full[i], inside = 0;
        for (int j = 0; j < nb && !inside; j++)
            inside = blocks[2 * j] < line && line < blocks[2 * j + 1];
        if (!inside)
            marks[line - lo] = 1;
    }
    for (int v = 0; v < span; v++)
        if (marks[v])
            out[m++] = lo + v;
    if (!has_draft(d, found, axis, out, m) && draft_action(g, p, d, axis, out, m) < 0)
        return -1;
    return 0;
}

typedef struct {
    double heuristic, cost;
    int axis, line, lo, hi;
} Half;

static int compare_halves(const void *x, const void *y)
{
    const Half *a = x, *b = y;
    int ba[3] = {a->lo, a->line, a->hi}, bb[3] = {b->lo, b->line, b->hi};
    Rank ra = {a->heuristic, a->cost, a->axis, ba, 3}, rb = {b->heuristic, b->cost, b->axis, bb, 3};
    return compare_ranks(&ra, &rb);
}

typedef struct {
    double cost;
    int line;
} Cheap;

static int compare_cheap(const void *x, const void *y)
{
    const Cheap *a = x, *b = y;
    if (a->cost != b->cost)
        return a->cost < b->cost ? -1 : 1;
    return (a->line > b->line) - (a->line < b->line);
}

/* ``Search._rank_in_two``. */
static int rank_in_two(Grid *g, const Place *p, int axis, int lo, int line, int hi, Half *out)
{
    int first[4], second[4];
    part_of(p, axis, lo, line, first);
    part_of(p, axis, line, hi, second);
    int same = labs(grid_quantum(g, axis, lo, line) - grid_quantum(g, axis, line, hi)) <=
               (hi - lo) + 2;
    if (same) {
        int a = grid_content(g, first[0], first[1], first[2], first[3]);
        int b = a < 0 ? -1 : grid_content(g, second[0], second[1], second[2], second[3]);
        if (a < 0 || b < 0)
            return -1;
        same = a == b;
    }
    out->cost = same ? g->repeat_cost + 1 : g->split_cost + 2;
    out->heuristic = out->cost + (0.0 + line_cost(p, axis, line));
    out->axis = axis, out->line = line, out->lo = lo, out->hi = hi;
    return 0;
}

/* The first repeated region's occurrence whose first row is ``row`` or above (the
 * occurrences are sorted by first row: ``bisect_left``). */
static int first_repeat_from(const Grid *g, int row)
{
    int a = 0, b = g->n_repeats;
    while (a < b) {
        int mid = (a + b) / 2;
        if (g->repeats[5 * mid] < row)
            a = mid + 1;
        else
            b = mid;
    }
    return a;
}

/* The drafts of ``Search._make_actions(region)``, best first, in d (from 0). 0 or -1. */
static int region_drafts(Grid *g, int r0, int r1, int c0, int c1, Drafts *d)
{
    Place p = {r0, r1, c0, c1, {NULL, NULL}, {0, 0}, NULL, 0};
    int result = -1, span = (r1 - r0) + (c1 - c0) + 2;
    int *lines[2] = {NULL, NULL}, n_lines[2] = {0, 0}, usable[2] = {0, 0};
    int *work = NULL;
    Half *halves = NULL;
    Cheap *cheap = NULL;
    int n_halves = 0;
    d->n = 0;
    d->pool_n = 0;
    lines[0] = PyMem_Malloc((size_t)(2 * span + 2) * sizeof(int));
    lines[1] = PyMem_Malloc((size_t)(2 * span + 2) * sizeof(int));
    halves = PyMem_Malloc((size_t)(2 * TOP_ACTIONS + 1) * sizeof(Half));
    cheap = PyMem_Malloc((size_t)(span + 1) * sizeof(Cheap));
    if (!lines[0] || !lines[1] || !halves || !cheap) {
        PyErr_NoMemory();
        goto end;
    }
    /* the lines of each axis, and how many element cells each crosses */
    int least[2] = {INT32_MAX, INT32_MAX}, n_fallback[2] = {0, 0};
    for (int axis = 0; axis < 2; axis++) {
        int *ln = lines[axis], *cr = lines[axis] + span + 1, n = 0, clean = 0;
        if (axis == 0) {
            for (int i = 0; i + 1 < c1 - c0; i++)
                if (CHX(g, r1, c0 + i) - CHX(g, r0, c0 + i) > 0)
                    ln[n] = c0 + 1 + i, cr[n++] = CRX(g, r1, c0 + i) - CRX(g, r0, c0 + i);
        } else {
            for (int i = 0; i + 1 < r1 - r0; i++)
                if (CHY(g, r0 + i, c1) - CHY(g, r0 + i, c0) > 0)
                    ln[n] = r0 + 1 + i, cr[n++] = CRY(g, r0 + i, c1) - CRY(g, r0 + i, c0);
        }
        for (int i = 0; i < n; i++)
            clean += cr[i] == 0;
        if (clean) {
            int m = 0;
            for (int i = 0; i < n; i++)
                if (cr[i] == 0)
                    ln[m++] = ln[i];
            n_lines[axis] = m, usable[axis] = 1;
        } else if (n) {
            for (int i = 0; i < n; i++)
                least[axis] = cr[i] < least[axis] ? cr[i] : least[axis];
            for (int i = 0; i < n; i++)
                if (cr[i] == least[axis])
                    cr[n_fallback[axis]++] = ln[i];
        }
    }
    if (!usable[0] && !usable[1]) { /* every line cuts an element: the fewest cells */
        if (!n_fallback[0] && !n_fallback[1]) {
            PyErr_Format(PyExc_ValueError, "region (%d, %d, %d, %d) has one label and no rule",
                         r0, r1, c0, c1);
            goto end;
        }
        int axis = !n_fallback[0] ? 1 : !n_fallback[1] ? 0 : least[1] < least[0] ? 1 : 0;
        memcpy(lines[axis], lines[axis] + span + 1, (size_t)n_fallback[axis] * sizeof(int));
        n_lines[axis] = n_fallback[axis], usable[axis] = 1;
    }
    /* the repeated regions' occurrences inside the region: those starting in its rows */
    {
        int from = first_repeat_from(g, r0), to = first_repeat_from(g, r1);
        p.inside = PyMem_Malloc((size_t)(to - from + 1) * sizeof(int));
        if (!p.inside) {
            PyErr_NoMemory();
            goto end;
        }
        for (int k = from; k < to; k++) {
            const int32_t *rep = g->repeats + 5 * k;
            if (rep[1] <= r1 && rep[2] >= c0 && rep[3] <= c1)
                p.inside[p.n_inside++] = k;
        }
    }
    if (place_line_costs(g, &p, 0) < 0 || place_line_costs(g, &p, 1) < 0)
        goto end;
    work = PyMem_Malloc((size_t)(6 * span + 4 * p.n_inside + 8) * sizeof(int));
    if (!work) {
        PyErr_NoMemory();
        goto end;
    }
    for (int axis = 0; axis < 2; axis++) {
        if (!usable[axis])
            continue;
        int lo = axis == 0 ? c0 : r0, hi = axis == 0 ? c1 : r1, n = n_lines[axis];
        int *full = lines[axis] + span + 1; /* lo, the lines, hi */
        full[0] = lo;
        memcpy(full + 1, lines[axis], (size_t)n * sizeof(int));
        full[n + 1] = hi;
        Py_ssize_t found = 0; /* every axis's drafts so far are found ones */
        if (draft_action(g, &p, d, axis, full, n + 2) < 0 ||
            add_runs(g, &p, d, found, axis, full, n + 2, work) < 0 ||
            add_repeated(g, &p, d, found, axis, full, n + 2, work) < 0)
            goto end;
        if (n > 1) { /* cuts in two: the lines the heuristic likes best */
            for (int i = 0; i < n; i++)
                cheap[i].cost = line_cost(&p, axis, lines[axis][i]), cheap[i].line = lines[axis][i];
            qsort(cheap, (size_t)n, sizeof(Cheap), compare_cheap);
            for (int i = 0; i < n && i < TOP_ACTIONS; i++) {
                int b[3] = {lo, cheap[i].line, hi};
                if (!has_draft(d, 0, axis, b, 3) &&
                    rank_in_two(g, &p, axis, lo, cheap[i].line, hi, &halves[n_halves++]) < 0)
                    goto end;
            }
        }
    }
    if ((g->ext & EXT_GRIDSPLIT) && usable[0] && usable[1] &&
        (n_lines[0] + 1) * (n_lines[1] + 1) <= GRID_CELLS &&
        draft_grid(g, &p, d, lines[1], n_lines[1], lines[0], n_lines[0]) < 0)
        goto end;
    /* every structural cut, and the heuristic's best cuts in two to fill up the choice */
    sort_drafts(d, 0, d->n);
    if (d->n > TOP_ACTIONS)
        d->n = TOP_ACTIONS;
    qsort(halves, (size_t)n_halves, sizeof(Half), compare_halves);
    int take = TOP_ACTIONS - (int)d->n > TOP_ACTIONS / 2 ? TOP_ACTIONS - (int)d->n : TOP_ACTIONS / 2;
    for (int i = 0; i < n_halves && i < take; i++) {
        int b[3] = {halves[i].lo, halves[i].line, halves[i].hi};
        if (draft_action(g, &p, d, halves[i].axis, b, 3) < 0)
            goto end;
    }
    sort_drafts(d, 0, d->n);
    result = 0;
end:
    PyMem_Free(lines[0]);
    PyMem_Free(lines[1]);
    PyMem_Free(halves);
    PyMem_Free(cheap);
    PyMem_Free(work);
    PyMem_Free(p.inside);
    PyMem_Free(p.cost[0]);
    PyMem_Free(p.cost[1]);
    return result;
}

/* -- the table -------------------------------------------------------------------------- */

typedef struct {
    double cost, heuristic;
    int form;
    int owner;                       /* its entry */
    Py_ssize_t parts, needs, kids;   /* offsets in the pool */
    int n_parts, n_needs, n_kids;
    int op, axis, count, centre;     /* what it is, for ``describe`` */
    Py_ssize_t bounds, across;       /* offsets in the pool */
    int n_bounds, n_across;
} Action;

typedef struct {
    int key[5];      /* heap order: bottom to top, left to right, larger first */
    int cid;
    int first, count; /* its actions, consecutive ids; count -1: not provided yet */
    Py_ssize_t odds;  /* offset of its cumulative exp(-H) in the odds pool, or -1 */
} Entry;

typedef struct {
    PyObject_HEAD
    Grid grid;
    SeqSet entry_map;    /* (r0, r1, c0, c1) -> entry */
    Drafts drafts;
    Entry *entries;
    Py_ssize_t n_entries, entries_cap;
    Action *actions;
    Py_ssize_t n_actions, actions_cap;
    int *pool;
    Py_ssize_t pool_n, pool_cap;
    double *odds;
    Py_ssize_t odds_n, odds_cap;
    /* per content */
    Py_ssize_t n_contents, contents_cap;
    int *rule;        /* the action chosen in the grammar being built, or -1 */
    char *pending;    /* waiting on the heap */
    int *mark;        /* covered in the exploitation score being summed (== stamp) */
    int *kind_of;     /* survey: its rule's kind, or -1 */
    int *position;    /* survey: its rule's place in the grammar */
    int *first_of;    /* survey, by kind: the content met first with it, or -1 */
    Py_ssize_t kinds_cap;
    double *learned;  /* the value table: least cost found, or INFINITY */
    int **covered;    /* ... and the contents its rules split ([0]: how many) */
    int stamp;
    SeqSet kinds;     /* (form, part symbols) -> kind */
    /* the grammar being built: contents in the order their rules were chosen */
    int *order;
    Py_ssize_t order_n, order_cap;
    int *heap;
    Py_ssize_t heap_n, heap_cap;
    int *scratch;
    Py_ssize_t scratch_cap;
} Table;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int ensure_contents(Table *t, Py_ssize_t n)
{
    if (n <= t->n_contents)
        return 0;
    if (n > t->contents_cap) {
        Py_ssize_t cap = t->contents_cap ? t->contents_cap : 64;
        while (cap < n)
            cap *= 2;
#define RE(arr)                                                              \
    do {                                                                     \
        void *p_ = PyMem_Realloc(t->arr, (size_t)cap * sizeof(*t->arr));    \
        if (!p_) {                                                           \
            PyErr_NoMemory();                                                \
            return -1;                                                       \
        }                                                                    \
        t->arr = p_;                                                         \
    } while (0)
        RE(rule);
        RE(pending);
        RE(mark);
        RE(kind_of);
        RE(position);
        RE(learned);
        RE(covered);
#undef RE
        t->contents_cap = cap;
    }
    for (Py_ssize_t i = t->n_contents; i < n; i++) {
        t->rule[i] = -1;
        t->pending[i] = 0;
        t->mark[i] = 0;
        t->kind_of[i] = -1;
        t->position[i] = -1;
        t->learned[i] = INFINITY;
        t->covered[i] = NULL;
    }
    t->n_contents = n;
    return 0;
}

static int content_seen(Table *t, int cid)
{
    if (cid < 0) {
        PyErr_SetString(PyExc_ValueError, "content ids are not negative");
        return -1;
    }
    return ensure_contents(t, (Py_ssize_t)cid + 1);
}

static int pool_room(Table *t, Py_ssize_t n) { return GROW(t->pool, t->pool_cap, t->pool_n + n); }

/* The entry of a region, added the first time: -1 on error. */
static int entry_of(Table *t, int r0, int r1, int c0, int c1)
{
    int box[4] = {r0, r1, c0, c1}, added;
    Py_ssize_t e = seqset_add(&t->entry_map, box, 4, &added);
    if (e < 0 || !added)
        return (int)e;
    int cid = grid_content(&t->grid, r0, r1, c0, c1);
    if (cid < 0 || content_seen(t, cid) < 0 || GROW(t->entries, t->entries_cap, e + 1) < 0)
        return -1;
    Entry *entry = &t->entries[e];
    entry->key[0] = r0, entry->key[1] = c0, entry->key[2] = -r1, entry->key[3] = -c1;
    entry->key[4] = cid;
    entry->cid = cid;
    entry->first = 0;
    entry->count = -1;
    entry->odds = -1;
    t->n_entries = e + 1;
    return (int)e;
}

/* A draft made an action of entry e: its parts as symbols, its needs (non-terminal
 * contents, larger parts first, once each), its non-terminal parts as entries, its form. */
static int keep_draft(Table *t, int e, const Drafts *d, const Draft *x)
{
    Grid *g = &t->grid;
    int m = x->n_written;
    const int *w = DP(d, x->written), *c = DP(d, x->cids);
    if (pool_room(t, 3 * m + x->n_bounds + x->n_across) < 0 ||
        GROW(t->actions, t->actions_cap, t->n_actions + 1) < 0 ||
        buffer_room(g, 2 * m + x->n_bounds + x->n_across + 8) < 0)
        return -1;
    Action a;
    a.cost = x->cost, a.heuristic = x->heuristic, a.owner = e;
    a.op = x->op, a.axis = x->axis, a.count = x->count, a.centre = x->centre;
    a.bounds = t->pool_n, a.n_bounds = x->n_bounds;
    memcpy(t->pool + t->pool_n, DP(d, x->bounds), (size_t)x->n_bounds * sizeof(int));
    t->pool_n += x->n_bounds;
    a.across = t->pool_n, a.n_across = x->n_across;
    memcpy(t->pool + t->pool_n, DP(d, x->across), (size_t)x->n_across * sizeof(int));
    t->pool_n += x->n_across;
    a.parts = t->pool_n, a.n_parts = m;
    for (int i = 0; i < m; i++) {
        if (content_seen(t, c[i]) < 0)
            return -1;
        t->pool[t->pool_n++] = g->terminal[c[i]] >= 0 ? -1 - g->terminal[c[i]] : c[i];
    }
    /* needs: non-terminal parts by size (cells), ties in order, each content once */
    int *order = g->buffer, n = 0;
    for (int i = 0; i < m; i++)
        if (g->terminal[c[i]] < 0)
            order[n++] = i;
    for (int i = 1; i < n; i++) {
        int v = order[i], j = i;
        long cells = (long)(w[4 * v + 1] - w[4 * v]) * (w[4 * v + 3] - w[4 * v + 2]);
        while (j > 0) {
            int u = order[j - 1];
            long other = (long)(w[4 * u + 1] - w[4 * u]) * (w[4 * u + 3] - w[4 * u + 2]);
            if (other >= cells)
                break;
            order[j] = u;
            j--;
        }
        order[j] = v;
    }
    a.needs = t->pool_n, a.n_needs = 0;
    for (int i = 0; i < n; i++) {
        int cid = c[order[i]], seen = 0;
        for (int k = 0; k < a.n_needs && !seen; k++)
            seen = t->pool[a.needs + k] == cid;
        if (!seen)
            t->pool[t->pool_n++] = cid, a.n_needs++;
    }
    /* the form: the rule without its symbols */
    int *form = g->buffer, f = 0;
    if (x->op == OP_GRID) {
        const int *rows = DP(d, x->bounds), *cols = DP(d, x->across);
        form[f++] = OP_GRID;
        form[f++] = x->n_bounds;
        for (int i = 0; i + 1 < x->n_bounds; i++)
            form[f++] = (int)grid_quantum(g, 1, rows[i], rows[i + 1]);
        for (int j = 0; j + 1 < x->n_across; j++)
            form[f++] = (int)grid_quantum(g, 0, cols[j], cols[j + 1]);
    } else {
        form[f++] = x->op, form[f++] = x->axis, form[f++] = x->count, form[f++] = x->centre;
        for (int i = 0; i < m; i++) {
            const int *q = w + 4 * i;
            form[f++] = (int)(x->axis == 0 ? grid_quantum(g, 0, q[2], q[3])
                                           : grid_quantum(g, 1, q[0], q[1]));
        }
    }
    int added;
    Py_ssize_t number = seqset_add(&g->forms, form, f, &added);
    if (number < 0)
        return -1;
    a.form = (int)number;
    /* the non-terminal parts as entries (which may add entries) */
    a.kids = t->pool_n, a.n_kids = 0;
    for (int i = 0; i < m; i++) {
        if (g->terminal[c[i]] >= 0)
            continue;
        const int *q = w + 4 * i;
        int kid = entry_of(t, q[0], q[1], q[2], q[3]);
        if (kid < 0 || pool_room(t, 1) < 0)
            return -1;
        t->pool[t->pool_n++] = kid;
        a.n_kids++;
    }
    t->actions[t->n_actions++] = a;
    return 0;
}

/* The entry's actions, made the first time. 0, or -1 on error. */
static int provide(Table *t, int e)
{
    if (t->entries[e].count >= 0)
        return 0;
    if (!t->grid.repeats) {
        PyErr_SetString(PyExc_TypeError, "prepare the Table before the search");
        return -1;
    }
    const int *k = t->entries[e].key;
    Drafts *d = &t->drafts;
    if (region_drafts(&t->grid, k[0], -k[2], k[1], -k[3], d) < 0)
        return -1;
    int first = (int)t->n_actions;
    for (Py_ssize_t i = 0; i < d->n; i++)
        if (keep_draft(t, e, d, &d->items[i]) < 0) {
            t->n_actions = first;
            return -1;
        }
    t->entries[e].first = first; /* the entries array may have grown meanwhile */
    t->entries[e].count = (int)d->n;
    return 0;
}

/* -- building a grammar ------------------------------------------------------------------ */

static int entry_less(const Table *t, int a, int b)
{
    const int *x = t->entries[a].key, *y = t->entries[b].key;
    for (int i = 0; i < 5; i++)
        if (x[i] != y[i])
            return x[i] < y[i];
    return 0;
}

static int heap_push(Table *t, int e)
{
    if (GROW(t->heap, t->heap_cap, t->heap_n + 1) < 0)
        return -1;
    Py_ssize_t i = t->heap_n++;
    while (i > 0) {
        Py_ssize_t up = (i - 1) / 2;
        if (!entry_less(t, e, t->heap[up]))
            break;
        t->heap[i] = t->heap[up];
        i = up;
    }
    t->heap[i] = e;
    return 0;
}

static int heap_pop(Table *t)
{
    int top = t->heap[0], last = t->heap[--t->heap_n];
    Py_ssize_t i = 0, n = t->heap_n;
    for (;;) {
        Py_ssize_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && entry_less(t, t->heap[c + 1], t->heap[c]))
            c++;
        if (!entry_less(t, t->heap[c], last))
            break;
        t->heap[i] = t->heap[c];
        i = c;
    }
    if (n)
        t->heap[i] = last;
    return top;
}

static void clear_grammar(Table *t)
{
    for (Py_ssize_t i = 0; i < t->order_n; i++)
        t->rule[t->order[i]] = -1;
    for (Py_ssize_t i = 0; i < t->heap_n; i++)
        t->pending[t->entries[t->heap[i]].cid] = 0;
    t->order_n = 0;
    t->heap_n = 0;
}

typedef struct {
    int greedy;          /* the first action everywhere */
    double epsilon;
    double optimistic;   /* the value of a content not in the table */
    double stop_at;      /* monotonic seconds: stop (greedy: hard limit, ADP: soft limit) */
    Twister *rng;
} Chooser;

#define TIME_UP (-2)

/* The action an entry takes: greedy's, or ADP's (module search, ``Search.adp``). */
static int choose(Table *t, int e, const Chooser *how)
{
    if (how->stop_at < INFINITY && now() > how->stop_at)
        return TIME_UP;
    if (provide(t, e) < 0)
        return -1;
    const Entry *entry = &t->entries[e];
    int first = entry->first, n = entry->count;
    if (how->greedy || n == 1)
        return first;
    if (mt_random(how->rng) < how->epsilon) { /* exploration: the heuristic's odds */
        if (entry->odds < 0) {
            if (GROW(t->odds, t->odds_cap, t->odds_n + n) < 0)
                return -1;
            double low = t->actions[first].heuristic, sum = 0.0;
            for (int i = 0; i < n; i++) {
                sum += exp(low - t->actions[first + i].heuristic);
                t->odds[t->odds_n + i] = sum;
            }
            t->entries[e].odds = t->odds_n;
            t->odds_n += n;
        }
        const double *weights = t->odds + t->entries[e].odds;
        double x = mt_random(how->rng) * (weights[n - 1] + 0.0);
        int lo = 0, hi = n - 1; /* bisect.bisect(weights, x, 0, n - 1) */
        while (lo < hi) {
            int mid = (lo + hi) / 2;
            if (x < weights[mid])
                hi = mid;
            else
                lo = mid + 1;
        }
        return first + lo;
    }
    int chosen = first; /* exploitation: Eq. 4 with the value table */
    double least = INFINITY;
    for (int i = 0; i < n; i++) {
        const Action *a = &t->actions[first + i];
        double score = a->cost;
        int stamp = ++t->stamp;
        const int *needs = t->pool + a->needs;
        for (int j = 0; j < a->n_needs; j++) { /* larger parts first */
            if (score >= least)
                break; /* values only add up */
            int need = needs[j];
            if (t->rule[need] >= 0 || t->pending[need] || t->mark[need] == stamp)
                continue;
            if (t->learned[need] == INFINITY) {
                score += how->optimistic;
            } else {
                score += t->learned[need];
                const int *cov = t->covered[need];
                for (int k = 1; k <= cov[0]; k++)
                    t->mark[cov[k]] = stamp;
            }
        }
        if (score < least) {
            chosen = first + i;
            least = score;
        }
    }
    return chosen;
}

/* One grammar from the start entry into t->order (rules in t->rule): 0, TIME_UP or -1. */
static int build(Table *t, int start, const Chooser *how)
{
    clear_grammar(t);
    int cid = t->entries[start].cid;
    t->pending[cid] = 1;
    if (heap_push(t, start) < 0)
        return -1;
    while (t->heap_n) {
        int e = heap_pop(t);
        cid = t->entries[e].cid;
        t->pending[cid] = 0;
        int a = choose(t, e, how);
        if (a < 0) {
            clear_grammar(t);
            return a;
        }
        if (GROW(t->order, t->order_cap, t->order_n + 1) < 0)
            return -1;
        t->rule[cid] = a;
        t->order[t->order_n++] = cid;
        const Action *act = &t->actions[a];
        for (int k = 0; k < act->n_kids; k++) {
            int kid = t->pool[act->kids + k];
            int sub = t->entries[kid].cid;
            if (t->rule[sub] >= 0 || t->pending[sub])
                continue;
            t->pending[sub] = 1;
            if (heap_push(t, kid) < 0)
                return -1;
            act = &t->actions[a];
        }
    }
    return 0;
}

/* -- the merged cost and the value table --------------------------------------------- */

typedef struct {
    Py_ssize_t n, words;
    uint64_t *bits; /* per rule (in order), the rules it reaches, itself included */
} Reach;

static int visit_rule(Table *t, int cid, Reach *reach)
{
    if (t->kind_of[cid] >= 0)
        return t->kind_of[cid];
    const Action *a = &t->actions[t->rule[cid]];
    Py_ssize_t p = t->position[cid];
    uint64_t *bits = reach->bits + p * reach->words;
    bits[p / 64] |= (uint64_t)1 << (p % 64);
    int n = a->n_parts;
    int *symbols = PyMem_Malloc((size_t)(n + 1) * sizeof(int));
    if (!symbols) {
        PyErr_NoMemory();
        return -1;
    }
    symbols[0] = a->form;
    Py_ssize_t parts = a->parts;
    for (int i = 0; i < n; i++) {
        int sub = t->pool[parts + i];
        if (sub < 0) {
            symbols[i + 1] = sub; /* a terminal's label */
            continue;
        }
        int kind = visit_rule(t, sub, reach);
        if (kind < 0) {
            PyMem_Free(symbols);
            return -1;
        }
        symbols[i + 1] = kind;
        const uint64_t *below = reach->bits + t->position[sub] * reach->words;
        for (Py_ssize_t w = 0; w < reach->words; w++)
            bits[w] |= below[w];
    }
    int added;
    Py_ssize_t kind = seqset_add(&t->kinds, symbols, n + 1, &added);
    PyMem_Free(symbols);
    if (kind < 0)
        return -1;
    if (kind >= t->kinds_cap) {
        Py_ssize_t old = t->kinds_cap;
        if (GROW(t->first_of, t->kinds_cap, kind + 1) < 0)
            return -1;
        for (Py_ssize_t k = old; k < t->kinds_cap; k++)
            t->first_of[k] = -1;
    }
    t->kind_of[cid] = (int)kind;
    if (t->first_of[kind] < 0)
        t->first_of[kind] = cid;
    return (int)kind;
}

/* Eq. 1 over the merged rules of the grammar in t->order (rules that read the same count
 * once, for the rule met first), and per rule the rules it reaches. 0 or -1. */
static int survey(Table *t, double *cost, Reach *reach)
{
    Py_ssize_t n = t->order_n;
    reach->n = n;
    reach->words = (n + 63) / 64;
    reach->bits = PyMem_Calloc((size_t)(n * reach->words + 1), sizeof(uint64_t));
    if (!reach->bits) {
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++)
        t->position[t->order[i]] = (int)i;
    int failed = 0;
    for (Py_ssize_t i = 0; i < n && !failed; i++)
        failed = visit_rule(t, t->order[i], reach) < 0;
    double total = 0.0;
    for (Py_ssize_t i = 0; i < n; i++) {
        int cid = t->order[i];
        if (!failed && t->first_of[t->kind_of[cid]] == cid)
            total += t->actions[t->rule[cid]].cost;
    }
    for (Py_ssize_t i = 0; i < n; i++) { /* forget the survey's marks */
        int cid = t->order[i];
        if (t->kind_of[cid] >= 0)
            t->first_of[t->kind_of[cid]] = -1;
        t->kind_of[cid] = -1;
    }
    *cost = total;
    if (failed) {
        PyMem_Free(reach->bits);
        reach->bits = NULL;
        return -1;
    }
    return 0;
}

/* Each content's cost with every rule below it counted once, kept when the least yet, with
 * the contents those rules split. The sums run over the distinct rule costs in the order
 * met, as ``cost * count`` each, like the reference. 0 or -1. */
static int learn(Table *t, const Reach *reach)
{
    Py_ssize_t n = reach->n;
    if (!n)
        return 0;
    double *distinct = PyMem_Malloc((size_t)n * sizeof(double));
    int *group = PyMem_Malloc((size_t)n * sizeof(int));
    int *counts = PyMem_Malloc((size_t)n * sizeof(int));
    if (GROW(t->scratch, t->scratch_cap, n) < 0 || !distinct || !group || !counts) {
        PyMem_Free(distinct);
        PyMem_Free(group);
        PyMem_Free(counts);
        if (!PyErr_Occurred())
            PyErr_NoMemory();
        return -1;
    }
    int n_distinct = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        double c = t->actions[t->rule[t->order[i]]].cost;
        int g = 0;
        while (g < n_distinct && distinct[g] != c)
            g++;
        if (g == n_distinct)
            distinct[n_distinct++] = c;
        group[i] = g;
    }
    int failed = 0;
    for (Py_ssize_t i = 0; i < n && !failed; i++) {
        const uint64_t *bits = reach->bits + i * reach->words;
        memset(counts, 0, (size_t)n_distinct * sizeof(int));
        int members = 0;
        for (Py_ssize_t w = 0; w < reach->words; w++) {
            uint64_t word = bits[w];
            while (word) {
                int b = __builtin_ctzll(word);
                word &= word - 1;
                Py_ssize_t p = w * 64 + b;
                counts[group[p]]++;
                t->scratch[members++] = t->order[p];
            }
        }
        double total = 0.0;
        for (int g = 0; g < n_distinct; g++)
            total += distinct[g] * (double)counts[g];
        int cid = t->order[i];
        if (total < t->learned[cid] - 1e-12) {
            int *cov = PyMem_Realloc(t->covered[cid], (size_t)(members + 1) * sizeof(int));
            if (!cov) {
                PyErr_NoMemory();
                failed = 1;
                break;
            }
            cov[0] = members;
            memcpy(cov + 1, t->scratch, (size_t)members * sizeof(int));
            t->covered[cid] = cov;
            t->learned[cid] = total;
        }
    }
    PyMem_Free(distinct);
    PyMem_Free(group);
    PyMem_Free(counts);
    return failed ? -1 : 0;
}

static void forget_learned(Table *t)
{
    for (Py_ssize_t i = 0; i < t->n_contents; i++) {
        t->learned[i] = INFINITY;
        PyMem_Free(t->covered[i]);
        t->covered[i] = NULL;
    }
}

/* -- Python methods ---------------------------------------------------------------------- */

static PyObject *grammar_pairs(Table *t, const int *cids, const int *actions, Py_ssize_t n)
{
    PyObject *list = PyList_New(n);
    if (!list)
        return NULL;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *pair = Py_BuildValue("(ii)", cids[i], actions[i]);
        if (!pair) {
            Py_DECREF(list);
            return NULL;
        }
        PyList_SET_ITEM(list, i, pair);
    }
    return list;
}

static int order_actions(Table *t, int *out)
{
    for (Py_ssize_t i = 0; i < t->order_n; i++)
        out[i] = t->rule[t->order[i]];
    return 0;
}

static PyObject *current_pairs(Table *t)
{
    int *actions = PyMem_Malloc((size_t)(t->order_n + 1) * sizeof(int));
    if (!actions)
        return PyErr_NoMemory();
    order_actions(t, actions);
    PyObject *out = grammar_pairs(t, t->order, actions, t->order_n);
    PyMem_Free(actions);
    return out;
}

static int check_region(const Table *t, int r0, int r1, int c0, int c1)
{
    if (r0 < 0 || c0 < 0 || r1 > t->grid.rows || c1 > t->grid.cols || r0 >= r1 || c0 >= c1) {
        PyErr_SetString(PyExc_ValueError, "not a region of the tiling");
        return -1;
    }
    return 0;
}

/* entry(r0, r1, c0, c1) -> id: the region's entry, added the first time. */
static PyObject *Table_entry(Table *t, PyObject *args)
{
    int r0, r1, c0, c1;
    if (!PyArg_ParseTuple(args, "iiii", &r0, &r1, &c0, &c1) || check_region(t, r0, r1, c0, c1) < 0)
        return NULL;
    int e = entry_of(t, r0, r1, c0, c1);
    return e < 0 ? NULL : PyLong_FromLong(e);
}

static int check_entry(Table *t, int e)
{
    if (e < 0 || e >= t->n_entries) {
        PyErr_SetString(PyExc_ValueError, "unknown entry");
        return -1;
    }
    return 0;
}

/* action_id(entry, index) -> the id of the entry's index-th action (made if need be). */
static PyObject *Table_action_id(Table *t, PyObject *args)
{
    int e, index;
    if (!PyArg_ParseTuple(args, "ii", &e, &index) || check_entry(t, e) < 0 || provide(t, e) < 0)
        return NULL;
    if (index < 0 || index >= t->entries[e].count) {
        PyErr_SetString(PyExc_IndexError, "no such action");
        return NULL;
    }
    return PyLong_FromLong(t->entries[e].first + index);
}

/* explored() -> how many regions were offered actions. */
static PyObject *Table_explored(Table *t, PyObject *unused)
{
    Py_ssize_t n = 0;
    for (Py_ssize_t e = 0; e < t->n_entries; e++)
        n += t->entries[e].count >= 0;
    return PyLong_FromSsize_t(n);
}

static PyObject *ints(const int *v, int n)
{
    PyObject *out = PyTuple_New(n);
    for (int i = 0; out && i < n; i++) {
        PyObject *x = PyLong_FromLong(v[i]);
        if (!x) {
            Py_CLEAR(out);
            break;
        }
        PyTuple_SET_ITEM(out, i, x);
    }
    return out;
}

/* action(id) -> ((r0, r1, c0, c1), axis, bounds, across, heuristic): the region an action
 * splits, its cuts and its heuristic value (the rest follows from them: ``Search._action``). */
static PyObject *Table_action(Table *t, PyObject *args)
{
    int id;
    if (!PyArg_ParseTuple(args, "i", &id))
        return NULL;
    if (id < 0 || id >= t->n_actions) {
        PyErr_SetString(PyExc_IndexError, "no such action");
        return NULL;
    }
    const Action *a = &t->actions[id];
    const Entry *e = &t->entries[a->owner];
    return Py_BuildValue("((iiii)sNNd)", e->key[0], -e->key[2], e->key[1], -e->key[3],
                         a->axis ? "y" : "x", ints(t->pool + a->bounds, a->n_bounds),
                         ints(t->pool + a->across, a->n_across), a->heuristic);
}

/* describe(entry) -> [(op, axis, bounds, across, count, centre, cost, heuristic)], best
 * first: the entry's actions (op: "split", "repeat", "repeatABA", "symsplit", "gridsplit"). */
static PyObject *Table_describe(Table *t, PyObject *args)
{
    static const char *ops[] = {"split", "repeat", "repeatABA", "symsplit", "gridsplit"};
    int e;
    if (!PyArg_ParseTuple(args, "i", &e) || check_entry(t, e) < 0 || provide(t, e) < 0)
        return NULL;
    const Entry *entry = &t->entries[e];
    PyObject *list = PyList_New(entry->count);
    for (int i = 0; list && i < entry->count; i++) {
        const Action *a = &t->actions[entry->first + i];
        PyObject *item = Py_BuildValue(
            "(ssNNiidd)", ops[a->op], a->axis ? "y" : "x", ints(t->pool + a->bounds, a->n_bounds),
            ints(t->pool + a->across, a->n_across), a->count, a->centre, a->cost, a->heuristic);
        if (!item) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, i, item);
    }
    return list;
}

/* greedy(start, stop_at) -> [(content, action)] in the order chosen, or None when the
 * clock passed stop_at (monotonic seconds) first. */
static PyObject *Table_greedy(Table *t, PyObject *args)
{
    int start;
    double stop_at;
    if (!PyArg_ParseTuple(args, "id", &start, &stop_at) || check_entry(t, start) < 0)
        return NULL;
    Chooser how = {1, 0.0, 0.0, stop_at, NULL};
    int done = build(t, start, &how);
    if (done == -1)
        return NULL;
    if (done == TIME_UP)
        Py_RETURN_NONE;
    return current_pairs(t);
}

static int set_grammar(Table *t, PyObject *seq)
{
    clear_grammar(t);
    PyObject *fast = PySequence_Fast(seq, "expected a sequence of action ids");
    if (!fast)
        return -1;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(fast);
    if (GROW(t->order, t->order_cap, n) < 0) {
        Py_DECREF(fast);
        return -1;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
        long a = PyLong_AsLong(PySequence_Fast_GET_ITEM(fast, i));
        if (a < 0 || a >= t->n_actions) {
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_ValueError, "unknown action");
            clear_grammar(t);
            Py_DECREF(fast);
            return -1;
        }
        int cid = t->entries[t->actions[a].owner].cid;
        if (t->rule[cid] >= 0) {
            PyErr_SetString(PyExc_ValueError, "two rules for one content");
            clear_grammar(t);
            Py_DECREF(fast);
            return -1;
        }
        t->rule[cid] = (int)a;
        t->order[t->order_n++] = cid;
    }
    Py_DECREF(fast);
    for (Py_ssize_t i = 0; i < n; i++) { /* every non-terminal part has its rule */
        const Action *a = &t->actions[t->rule[t->order[i]]];
        for (int k = 0; k < a->n_parts; k++) {
            int sub = t->pool[a->parts + k];
            if (sub >= 0 && t->rule[sub] < 0) {
                PyErr_SetString(PyExc_ValueError, "a part without a rule");
                clear_grammar(t);
                return -1;
            }
        }
    }
    return 0;
}

/* survey(actions) -> (cost, reach): Eq. 1 over the merged rules of the grammar whose rules
 * are these actions (in order), and per rule the positions of the rules it reaches. */
static PyObject *Table_survey(Table *t, PyObject *args)
{
    PyObject *seq;
    if (!PyArg_ParseTuple(args, "O", &seq) || set_grammar(t, seq) < 0)
        return NULL;
    double cost;
    Reach reach = {0, 0, NULL};
    if (survey(t, &cost, &reach) < 0) {
        clear_grammar(t);
        return NULL;
    }
    PyObject *rows = PyList_New(reach.n);
    for (Py_ssize_t i = 0; rows && i < reach.n; i++) {
        PyObject *row = PyList_New(0);
        if (!row) {
            Py_CLEAR(rows);
            break;
        }
        PyList_SET_ITEM(rows, i, row);
        for (Py_ssize_t p = 0; p < reach.n; p++) {
            if (!((reach.bits[i * reach.words + p / 64] >> (p % 64)) & 1))
                continue;
            PyObject *v = PyLong_FromSsize_t(p);
            if (!v || PyList_Append(row, v) < 0) {
                Py_XDECREF(v);
                Py_CLEAR(rows);
                break;
            }
            Py_DECREF(v);
        }
    }
    PyMem_Free(reach.bits);
    clear_grammar(t);
    if (!rows)
        return NULL;
    return Py_BuildValue("(dN)", cost, rows);
}

/* adp(start, greedy, iterations, state, optimistic, stop_at) -> (best, best_at, done):
 * see ``Search.adp``. ``greedy``: its actions in order; ``state``: random.getstate()[1]. */
static PyObject *Table_adp(Table *t, PyObject *args)
{
    int start, iterations;
    PyObject *greedy, *state;
    double optimistic, stop_at;
    if (!PyArg_ParseTuple(args, "iOiOdd", &start, &greedy, &iterations, &state, &optimistic,
                          &stop_at) ||
        check_entry(t, start) < 0)
        return NULL;
    Twister rng;
    PyObject *fast = PySequence_Fast(state, "expected random.getstate()[1]");
    if (!fast)
        return NULL;
    if (PySequence_Fast_GET_SIZE(fast) != MT_N + 1) {
        Py_DECREF(fast);
        PyErr_SetString(PyExc_ValueError, "expected 625 ints of state");
        return NULL;
    }
    for (int i = 0; i <= MT_N; i++) {
        unsigned long v = PyLong_AsUnsignedLong(PySequence_Fast_GET_ITEM(fast, i));
        if (v == (unsigned long)-1 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return NULL;
        }
        if (i < MT_N)
            rng.state[i] = (uint32_t)v;
        else
            rng.index = (int)v;
    }
    Py_DECREF(fast);

    PyObject *result = NULL;
    int *best = NULL, *best_cids = NULL;
    Py_ssize_t best_n = 0;
    SeqSet seen = {0};
    Reach reach = {0, 0, NULL};
    double cost, best_cost;
    int best_at = 0, done = iterations;
    forget_learned(t);
    if (set_grammar(t, greedy) < 0 || survey(t, &best_cost, &reach) < 0 || learn(t, &reach) < 0)
        goto end;
    PyMem_Free(reach.bits);
    reach.bits = NULL;
    best_n = t->order_n;
    best = PyMem_Malloc((size_t)(best_n + 1) * sizeof(int));
    best_cids = PyMem_Malloc((size_t)(best_n + 1) * sizeof(int));
    if (!best || !best_cids) {
        PyErr_NoMemory();
        goto end;
    }
    order_actions(t, best);
    memcpy(best_cids, t->order, (size_t)best_n * sizeof(int));
    Chooser how = {0, 1.0, optimistic, stop_at, &rng};
    for (int it = 1; it < iterations; it++) {
        how.epsilon = 1.0 - (double)it / (double)iterations;
        int built = build(t, start, &how);
        if (built == -1 && PyErr_ExceptionMatches(BudgetError)) {
            PyErr_Clear(); /* stops as the time limit does: the best grammar so far */
            clear_grammar(t);
            done = it;
            break;
        }
        if (built == -1)
            goto end;
        if (built == TIME_UP) {
            done = it;
            break;
        }
        /* each action is one region's, so the actions tell the contents too */
        if (GROW(t->scratch, t->scratch_cap, t->order_n + 1) < 0)
            goto end;
        order_actions(t, t->scratch);
        int added;
        if (seqset_add(&seen, t->scratch, (int)t->order_n, &added) < 0)
            goto end;
        if (!added)
            continue;
        if (survey(t, &cost, &reach) < 0 || learn(t, &reach) < 0)
            goto end;
        PyMem_Free(reach.bits);
        reach.bits = NULL;
        if (cost < best_cost - 1e-9) {
            int *b = PyMem_Realloc(best, (size_t)(t->order_n + 1) * sizeof(int));
            int *c = b ? PyMem_Realloc(best_cids, (size_t)(t->order_n + 1) * sizeof(int)) : NULL;
            if (b)
                best = b;
            if (c)
                best_cids = c;
            if (!b || !c) {
                PyErr_NoMemory();
                goto end;
            }
            best_n = t->order_n;
            order_actions(t, best);
            memcpy(best_cids, t->order, (size_t)best_n * sizeof(int));
            best_cost = cost;
            best_at = it;
        }
    }
    {
        PyObject *pairs = grammar_pairs(t, best_cids, best, best_n);
        if (pairs)
            result = Py_BuildValue("(Nii)", pairs, best_at, done);
    }
end:
    PyMem_Free(reach.bits);
    PyMem_Free(best);
    PyMem_Free(best_cids);
    seqset_free(&seen);
    clear_grammar(t);
    forget_learned(t);
    return result;
}

/* Table(labels, rows, cols, xs, ys, qx, qy, background): a tiling, its labels (int32, rows
 * x cols, bottom row first), its cuts (float64), the size quanta and the background's label
 * (or -1). Its contents can be asked for at once; ``prepare`` readies it for the search. */
static int Table_init(Table *t, PyObject *args, PyObject *kwds)
{
    Py_buffer labels, xs, ys;
    int rows, cols, background;
    double qx, qy;
    if (t->grid.labels) {
        PyErr_SetString(PyExc_TypeError, "a Table is made once");
        return -1;
    }
    if (!PyArg_ParseTuple(args, "y*iiy*y*ddi", &labels, &rows, &cols, &xs, &ys, &qx, &qy,
                          &background))
        return -1;
    int ok = rows > 0 && cols > 0 && labels.len == (Py_ssize_t)rows * cols * 4 &&
             xs.len == (Py_ssize_t)(cols + 1) * 8 && ys.len == (Py_ssize_t)(rows + 1) * 8 &&
             qx > 0 && qy > 0;
    Grid *g = &t->grid;
    if (ok) {
        g->rows = rows, g->cols = cols, g->qx = qx, g->qy = qy;
        g->labels = PyMem_Malloc((size_t)labels.len);
        g->xs = PyMem_Malloc((size_t)xs.len);
        g->ys = PyMem_Malloc((size_t)ys.len);
        if (g->labels && g->xs && g->ys) {
            memcpy(g->labels, labels.buf, (size_t)labels.len);
            memcpy(g->xs, xs.buf, (size_t)xs.len);
            memcpy(g->ys, ys.buf, (size_t)ys.len);
        } else {
            PyErr_NoMemory();
            ok = -1;
        }
    } else {
        PyErr_SetString(PyExc_ValueError, "the tiling's arrays do not match its size");
    }
    PyBuffer_Release(&labels);
    PyBuffer_Release(&xs);
    PyBuffer_Release(&ys);
    if (ok != 1 || grid_prefixes(g, background) < 0)
        return -1;
    g->cells_max = LLONG_MAX; /* until ``limit`` */
    return 0;
}

/* prepare(repeats, extensions, split, repeat): the repeated regions' occurrences (int32,
 * five a row: r0, r1, c0, c1, cells, by first row), the extensions as bits (1 repeatABA, 2
 * symsplit, 4 gridsplit) and the rule costs; once, before the search. */
static PyObject *Table_prepare(Table *t, PyObject *args)
{
    Py_buffer repeats;
    int ext;
    double split, repeat;
    Grid *g = &t->grid;
    if (!g->labels || g->repeats) {
        PyErr_SetString(PyExc_TypeError, "prepare a made Table, once");
        return NULL;
    }
    if (!PyArg_ParseTuple(args, "y*idd", &repeats, &ext, &split, &repeat))
        return NULL;
    if (repeats.len % 20) {
        PyBuffer_Release(&repeats);
        PyErr_SetString(PyExc_ValueError, "repeats come five int32 a row");
        return NULL;
    }
    g->repeats = PyMem_Malloc((size_t)repeats.len + 20);
    if (!g->repeats) {
        PyBuffer_Release(&repeats);
        return PyErr_NoMemory();
    }
    memcpy(g->repeats, repeats.buf, (size_t)repeats.len);
    g->n_repeats = (int)(repeats.len / 20);
    g->ext = ext, g->split_cost = split, g->repeat_cost = repeat;
    PyBuffer_Release(&repeats);
    Py_RETURN_NONE;
}

/* content(r0, r1, c0, c1) -> (content, label): the region's content (``Grid.content``) and
 * its label when it is one terminal, else -1. */
static PyObject *Table_content(Table *t, PyObject *args)
{
    int r0, r1, c0, c1;
    if (!PyArg_ParseTuple(args, "iiii", &r0, &r1, &c0, &c1) || check_region(t, r0, r1, c0, c1) < 0)
        return NULL;
    int cid = grid_content(&t->grid, r0, r1, c0, c1);
    if (cid < 0)
        return NULL;
    return Py_BuildValue("(ii)", cid, t->grid.terminal[cid]);
}

/* limit(cells): the most cells the contents may read and keep (``regions.Grid``). */
static PyObject *Table_limit(Table *t, PyObject *args)
{
    long long cells;
    if (!PyArg_ParseTuple(args, "L", &cells))
        return NULL;
    t->grid.cells_max = cells;
    Py_RETURN_NONE;
}

static PyObject *Table_spent(Table *t, PyObject *unused)
{
    return PyBool_FromLong(t->grid.spent);
}

static PyObject *Table_cells_read(Table *t, PyObject *unused)
{
    return PyLong_FromLongLong(t->grid.cells_read);
}

static void Table_dealloc(Table *t)
{
    grid_free(&t->grid);
    seqset_free(&t->entry_map);
    PyMem_Free(t->drafts.items);
    PyMem_Free(t->drafts.pool);
    for (Py_ssize_t i = 0; i < t->n_contents; i++)
        PyMem_Free(t->covered[i]);
    PyMem_Free(t->entries);
    PyMem_Free(t->actions);
    PyMem_Free(t->pool);
    PyMem_Free(t->odds);
    PyMem_Free(t->rule);
    PyMem_Free(t->pending);
    PyMem_Free(t->mark);
    PyMem_Free(t->kind_of);
    PyMem_Free(t->position);
    PyMem_Free(t->first_of);
    PyMem_Free(t->learned);
    PyMem_Free(t->covered);
    PyMem_Free(t->order);
    PyMem_Free(t->heap);
    PyMem_Free(t->scratch);
    seqset_free(&t->kinds);
    Py_TYPE(t)->tp_free((PyObject *)t);
}

static PyMethodDef Table_methods[] = {
    {"prepare", (PyCFunction)Table_prepare, METH_VARARGS,
     "prepare(repeats, extensions, split, repeat): ready the Table for the search."},
    {"limit", (PyCFunction)Table_limit, METH_VARARGS,
     "limit(cells): the most cells the contents may read (BudgetError past it)."},
    {"spent", (PyCFunction)Table_spent, METH_NOARGS,
     "spent() -> whether a content was refused because the budget ran out."},
    {"cells_read", (PyCFunction)Table_cells_read, METH_NOARGS,
     "cells_read() -> the cells the contents have read so far."},
    {"content", (PyCFunction)Table_content, METH_VARARGS,
     "content(r0, r1, c0, c1) -> (content, label or -1)."},
    {"entry", (PyCFunction)Table_entry, METH_VARARGS,
     "entry(r0, r1, c0, c1) -> id: the region's entry, added the first time."},
    {"action_id", (PyCFunction)Table_action_id, METH_VARARGS,
     "action_id(entry, index) -> the id of the entry's index-th action."},
    {"action", (PyCFunction)Table_action, METH_VARARGS,
     "action(id) -> (r0, r1, c0, c1, index): its region and its place among its actions."},
    {"explored", (PyCFunction)Table_explored, METH_NOARGS,
     "explored() -> how many regions were offered actions."},
    {"describe", (PyCFunction)Table_describe, METH_VARARGS,
     "describe(entry) -> [(op, axis, bounds, across, count, centre, cost, heuristic)]."},
    {"greedy", (PyCFunction)Table_greedy, METH_VARARGS,
     "greedy(start, stop_at) -> [(content, action)], or None past stop_at."},
    {"survey", (PyCFunction)Table_survey, METH_VARARGS,
     "survey(actions) -> (cost, reach): Eq. 1 over the merged rules, and what each reaches."},
    {"adp", (PyCFunction)Table_adp, METH_VARARGS,
     "adp(start, greedy, iterations, state, optimistic, stop_at) -> (best, best_at, done)."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject TableType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "facadecli.grammar._adp.Table",
    .tp_basicsize = sizeof(Table),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "Regions, their actions and the value table of one grammar search.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Table_init,
    .tp_dealloc = (destructor)Table_dealloc,
    .tp_methods = Table_methods,
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_adp", "The grammar search's inner loop (see _adp.c).", -1,
    NULL, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__adp(void)
{
    if (PyType_Ready(&TableType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
    Py_INCREF(&TableType);
    if (PyModule_AddObject(m, "Table", (PyObject *)&TableType) < 0) {
        Py_DECREF(&TableType);
        Py_DECREF(m);
        return NULL;
    }
    BudgetError = PyErr_NewException("facadecli.grammar._adp.BudgetError", NULL, NULL);
    if (!BudgetError || PyModule_AddObject(m, "BudgetError", BudgetError) < 0) {
        Py_XDECREF(BudgetError);
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(BudgetError); /* the module holds one reference, this file the other */
    return m;
}
