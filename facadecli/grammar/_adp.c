/* The inner loop of the grammar search (facadecli.grammar.search): building grammars region
 * by region (greedy, or ADP's explore-or-exploit choice), the merged cost of a grammar and
 * the value table it teaches. Regions and their actions are made in Python (``Search``) and
 * handed over once each, through the ``provide`` callback; everything here is integers and
 * floats.
 *
 * It computes exactly what the plain Python loop does (tests/adp_reference.py), to the bit:
 * the same Mersenne Twister draws as ``random.Random`` (its state is handed over), the same
 * sums in the same order, the same tie rules. Only the speed differs.
 *
 * Ids: an *entry* is a region to split (its heap key and content); an *action* is one rule
 * an entry may take; a *content* is what regions read (``Grid.content``). An action's parts
 * are written as symbols: a content for a non-terminal, -1 - label for a terminal.
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
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

/* -- the table -------------------------------------------------------------------------- */

typedef struct {
    double cost, heuristic;
    int form;
    int owner;                       /* its entry */
    Py_ssize_t parts, needs, kids;   /* offsets in the pool */
    int n_parts, n_needs, n_kids;
} Action;

typedef struct {
    int key[5];      /* heap order: bottom to top, left to right, larger first */
    int cid;
    int first, count; /* its actions, consecutive ids; count -1: not provided yet */
    Py_ssize_t odds;  /* offset of its cumulative exp(-H) in the odds pool, or -1 */
} Entry;

typedef struct {
    PyObject_HEAD
    PyObject *provide;   /* entry id -> [(cost, heuristic, form, parts, needs, kids)] */
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

/* Ints of a Python sequence appended to the pool; checks contents or entries. */
static int pool_ints(Table *t, PyObject *seq, Py_ssize_t *at, int *n, int what)
{
    PyObject *fast = PySequence_Fast(seq, "expected a sequence of ints");
    if (!fast)
        return -1;
    Py_ssize_t len = PySequence_Fast_GET_SIZE(fast);
    if (GROW(t->pool, t->pool_cap, t->pool_n + len) < 0) {
        Py_DECREF(fast);
        return -1;
    }
    *at = t->pool_n;
    *n = (int)len;
    for (Py_ssize_t i = 0; i < len; i++) {
        long v = PyLong_AsLong(PySequence_Fast_GET_ITEM(fast, i));
        if (v == -1 && PyErr_Occurred()) {
            Py_DECREF(fast);
            return -1;
        }
        if (what == 1 && v >= 0 && content_seen(t, (int)v) < 0) { /* a part */
            Py_DECREF(fast);
            return -1;
        }
        if (what == 2 && content_seen(t, (int)v) < 0) { /* a need */
            Py_DECREF(fast);
            return -1;
        }
        if (what == 3 && (v < 0 || v >= t->n_entries)) { /* a kid */
            Py_DECREF(fast);
            PyErr_SetString(PyExc_ValueError, "unknown entry");
            return -1;
        }
        t->pool[t->pool_n++] = (int)v;
    }
    Py_DECREF(fast);
    return 0;
}

/* The entry's actions, asked of Python the first time. 0, or -1 on error. */
static int provide(Table *t, int e)
{
    if (t->entries[e].count >= 0)
        return 0;
    PyObject *list = PyObject_CallFunction(t->provide, "i", e);
    if (!list)
        return -1;
    PyObject *fast = PySequence_Fast(list, "provide() must give a list of actions");
    Py_DECREF(list);
    if (!fast)
        return -1;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(fast);
    if (n < 1) {
        Py_DECREF(fast);
        PyErr_SetString(PyExc_ValueError, "a region without actions");
        return -1;
    }
    if (GROW(t->actions, t->actions_cap, t->n_actions + n) < 0) {
        Py_DECREF(fast);
        return -1;
    }
    int first = (int)t->n_actions;
    for (Py_ssize_t i = 0; i < n; i++) {
        Action a;
        PyObject *parts, *needs, *kids;
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(fast, i), "ddiOOO", &a.cost, &a.heuristic,
                              &a.form, &parts, &needs, &kids) ||
            pool_ints(t, parts, &a.parts, &a.n_parts, 1) < 0 ||
            pool_ints(t, needs, &a.needs, &a.n_needs, 2) < 0 ||
            pool_ints(t, kids, &a.kids, &a.n_kids, 3) < 0) {
            Py_DECREF(fast);
            t->n_actions = first;
            return -1;
        }
        a.owner = e;
        t->actions[t->n_actions++] = a;
    }
    Py_DECREF(fast);
    t->entries[e].first = first; /* the entries array may have grown meanwhile */
    t->entries[e].count = (int)n;
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

static PyObject *Table_add_entry(Table *t, PyObject *args)
{
    int key[5];
    if (!PyArg_ParseTuple(args, "(iiiii)", &key[0], &key[1], &key[2], &key[3], &key[4]))
        return NULL;
    if (content_seen(t, key[4]) < 0 || GROW(t->entries, t->entries_cap, t->n_entries + 1) < 0)
        return NULL;
    Entry *e = &t->entries[t->n_entries];
    memcpy(e->key, key, sizeof(key));
    e->cid = key[4];
    e->first = 0;
    e->count = -1;
    e->odds = -1;
    return PyLong_FromSsize_t(t->n_entries++);
}

static int check_entry(Table *t, int e)
{
    if (e < 0 || e >= t->n_entries) {
        PyErr_SetString(PyExc_ValueError, "unknown entry");
        return -1;
    }
    return 0;
}

/* provide(entry): ask for the entry's actions now, when not yet given. */
static PyObject *Table_provide(Table *t, PyObject *args)
{
    int e;
    if (!PyArg_ParseTuple(args, "i", &e) || check_entry(t, e) < 0 || provide(t, e) < 0)
        return NULL;
    Py_RETURN_NONE;
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

static int Table_init(Table *t, PyObject *args, PyObject *kwds)
{
    PyObject *provide;
    static char *names[] = {"provide", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "O", names, &provide))
        return -1;
    if (!PyCallable_Check(provide)) {
        PyErr_SetString(PyExc_TypeError, "provide must be callable");
        return -1;
    }
    Py_INCREF(provide);
    Py_XDECREF(t->provide);
    t->provide = provide;
    return 0;
}

static int Table_traverse(Table *t, visitproc visit, void *arg)
{
    Py_VISIT(t->provide);
    return 0;
}

static int Table_clear(Table *t)
{
    Py_CLEAR(t->provide);
    return 0;
}

static void Table_dealloc(Table *t)
{
    PyObject_GC_UnTrack(t);
    Table_clear(t);
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
    {"add_entry", (PyCFunction)Table_add_entry, METH_VARARGS,
     "add_entry(key) -> id: a region to split, by its heap key (r0, c0, -r1, -c1, content)."},
    {"provide", (PyCFunction)Table_provide, METH_VARARGS,
     "provide(entry): ask for the entry's actions now, when not given yet."},
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
    .tp_flags = Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC,
    .tp_doc = "Regions, their actions and the value table of one grammar search.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Table_init,
    .tp_dealloc = (destructor)Table_dealloc,
    .tp_traverse = (traverseproc)Table_traverse,
    .tp_clear = (inquiry)Table_clear,
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
    return m;
}
