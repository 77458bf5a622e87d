# The C types of adp.py where Cython compiles it (setup.py); adp.py stays plain Python and
# runs as it is where there is no C compiler. Only types here: no logic.
cimport cython


cdef int EXT_ABA, EXT_SYMSPLIT, EXT_GRIDSPLIT
cdef int OP_SPLIT, OP_REPEAT, OP_ABA, OP_SYMSPLIT, OP_GRID
cdef int TOP_ACTIONS, GRID_CELLS, TIME_UP, FAILED, CLOCK_EVERY
cdef double INF
cdef unsigned long long M32, M64, ONE, DE_BRUIJN, FNV_OFFSET, FNV_PRIME
cdef int A_OWNER, A_OP, A_AXIS, A_COUNT, A_CENTRE, A_FORM
cdef int A_BOUNDS, A_N_BOUNDS, A_ACROSS, A_N_ACROSS, A_PARTS, A_N_PARTS
cdef int A_NEEDS, A_N_NEEDS, A_KIDS, A_N_KIDS, A_FIELDS
cdef int D_AXIS, D_OP, D_COUNT, D_CENTRE, D_BOUNDS, D_N_BOUNDS, D_ACROSS, D_N_ACROSS, D_CIDS, D_M
cdef int D_FIELDS
cdef object _INTS, _LONGS, _DOUBLES, _WORDS, _FLAGS

cdef object _ints(Py_ssize_t n)
cdef object _longs(Py_ssize_t n)
cdef object _doubles(Py_ssize_t n)
cdef object _words(Py_ssize_t n)
cdef object _flags(Py_ssize_t n)

@cython.locals(cap=Py_ssize_t)
cdef Py_ssize_t _capacity(Py_ssize_t have, Py_ssize_t need) noexcept

@cython.locals(made=object, view="int[::1]", i=Py_ssize_t)
cdef object _more_ints(int[::1] old, Py_ssize_t used, Py_ssize_t need, int fill)

@cython.locals(made=object, view="double[::1]")
cdef object _more_doubles(double[::1] old, Py_ssize_t used, Py_ssize_t need)

@cython.locals(made=object, view="long long[::1]")
cdef object _more_longs(long long[::1] old, Py_ssize_t used, Py_ssize_t need)

@cython.locals(made=object, view="signed char[::1]")
cdef object _more_flags(signed char[::1] old, Py_ssize_t used, Py_ssize_t need)

@cython.final
cdef class SeqSet:
    cdef int[::1] pool
    cdef long long[::1] at
    cdef unsigned long long[::1] slots
    cdef Py_ssize_t n_slots, n, pool_n
    cdef public bint added

    @cython.locals(h="unsigned long long", i=Py_ssize_t)
    cdef inline unsigned long long hash(self, int[::1] v, Py_ssize_t start, Py_ssize_t n) noexcept

    @cython.locals(mask=Py_ssize_t, h="unsigned long long", j=Py_ssize_t, s=Py_ssize_t,
                   at=Py_ssize_t, same=bint, i=Py_ssize_t)
    cdef Py_ssize_t add(self, int[::1] v, Py_ssize_t start, Py_ssize_t n) except -1

    cdef void clear(self) except *

    @cython.locals(slots="unsigned long long[::1]", mask=Py_ssize_t, i=Py_ssize_t,
                   s="unsigned long long", h="unsigned long long", j=Py_ssize_t)
    cdef void rehash(self, Py_ssize_t n_slots) except *


@cython.final
cdef class Table:
    cdef int rows, cols
    cdef int[::1] labels
    cdef double[::1] xs, ys
    cdef double qx, qy
    cdef int[::1] change_x, cross_x, change_y, cross_y
    cdef bint prepared
    cdef int[::1] repeats
    cdef int n_repeats, ext
    cdef double split_cost, repeat_cost
    cdef long long cells_read, cells_max
    cdef bint spent_
    cdef SeqSet keys, regions, forms, entry_map, kinds
    cdef int[::1] terminal, region_cid, buffer, form
    cdef Py_ssize_t n_entries
    cdef int[::1] e_key, e_cid, e_first, e_count, e_odds
    cdef Py_ssize_t n_actions
    cdef double[::1] a_cost, a_heuristic
    cdef int[::1] a_int
    cdef int[::1] pool
    cdef Py_ssize_t pool_n
    cdef double[::1] odds
    cdef Py_ssize_t odds_n
    cdef Py_ssize_t n_contents
    cdef int[::1] rule
    cdef signed char[::1] pending
    cdef int[::1] mark, kind_of, position
    cdef double[::1] learned
    cdef int[::1] covered, cover
    cdef Py_ssize_t cover_n
    cdef int[::1] first_of
    cdef int stamp
    cdef int[::1] order
    cdef Py_ssize_t order_n
    cdef int[::1] heap
    cdef Py_ssize_t heap_n
    cdef int[::1] scratch, symbols
    cdef Py_ssize_t d_stride
    cdef int d_r0, d_r1, d_c0, d_c1
    cdef int[::1] d_lines, d_crosses, d_full, d_runs, d_cheap, d_bounds, d_part, d_inside
    cdef int[::1] d_spans, d_int, d_order, d_pool, h_int
    cdef double[::1] d_cost, d_pos, d_neg, d_real, h_real
    cdef Py_ssize_t n_inside, n_drafts, n_order, d_pool_n, n_halves
    cdef Py_ssize_t symbols_n
    cdef unsigned long long[::1] bits
    cdef Py_ssize_t words
    cdef double[::1] distinct
    cdef int[::1] group, counts, bit_at
    cdef bint greedy_
    cdef double epsilon, optimistic, stop_at
    cdef long long ticks
    cdef object draw, clock

    @cython.locals(box="int[::1]", key="int[::1]", at=Py_ssize_t, w=int, h=int, need=Py_ssize_t,
                   starts_c=Py_ssize_t, starts_r=Py_ssize_t, nc=int, nr=int, cols1=int, cols2=int,
                   i=int, j=int, cost="long long", n=Py_ssize_t, row=Py_ssize_t, size=double,
                   cid=Py_ssize_t)
    cdef int grid_content(self, int r0, int r1, int c0, int c1) except -9

    cdef long quantum(self, int axis, int a, int b) except? -9

    @cython.locals(box="int[::1]", e=Py_ssize_t, cid=int, n=Py_ssize_t, at=Py_ssize_t)
    cdef int entry_of(self, int r0, int r1, int c0, int c1) except -9

    @cython.locals(n=Py_ssize_t, used=Py_ssize_t, i=Py_ssize_t)
    cdef int content_seen(self, int cid) except -9

    cdef int pool_room(self, Py_ssize_t n) except -9

    @cython.locals(at=Py_ssize_t, r0=int, r1=int, c0=int, c1=int, n=Py_ssize_t, first=Py_ssize_t,
                   k=Py_ssize_t)
    cdef int provide(self, int e) except -9

    @cython.locals(found0=int, found1=int, n0=int, n1=int, least0=int, least1=int, axis=int,
                   n=int, lo=int, hi=int, base=Py_ssize_t, i=int, cheap=int, k=int, take=int,
                   line=int)
    cdef Py_ssize_t drafts(self, int r0, int r1, int c0, int c1) except -1

    @cython.locals(r0=int, r1=int, c0=int, c1=int, base=Py_ssize_t, n=int, cols1=int, cols2=int,
                   i=int, at=Py_ssize_t)
    cdef int _found_lines(self, int axis) noexcept

    @cython.locals(base=Py_ssize_t, k=int, i=int)
    cdef int _lines_crossing(self, int axis, int n, int crosses) noexcept

    @cython.locals(base=Py_ssize_t, least=int, i=int)
    cdef int _least_crossed(self, int axis, int n) noexcept

    @cython.locals(base=Py_ssize_t, lo=int, k=int, i=int, line=int, c=double, j=int, m=int)
    cdef int _cheapest_lines(self, int axis, int n) noexcept

    @cython.locals(r1=int, c0=int, c1=int, first=int, last=int, n=Py_ssize_t, k=int,
                   at=Py_ssize_t)
    cdef int _inside(self) noexcept

    @cython.locals(a=int, b=int, mid=int)
    cdef int _first_repeat_from(self, int row) noexcept

    @cython.locals(r0=int, r1=int, c0=int, c1=int, lo=int, hi=int, base=Py_ssize_t, size=int,
                   i=int, k=Py_ssize_t, at=Py_ssize_t, start=int, stop=int, cells=double,
                   total=double, c=double)
    cdef int _line_costs(self, int axis) noexcept

    @cython.locals(base=Py_ssize_t, total=double, i=Py_ssize_t)
    cdef double _lines_cost(self, int axis, Py_ssize_t at, Py_ssize_t n) noexcept

    @cython.locals(d=Py_ssize_t)
    cdef Py_ssize_t _new_draft(self, Py_ssize_t ints) except -1

    cdef int _add_draft(self, Py_ssize_t d, double heuristic, double rule_cost) noexcept

    @cython.locals(k=Py_ssize_t, f=Py_ssize_t, at=Py_ssize_t, same=bint, i=Py_ssize_t)
    cdef bint _has_draft(self, int axis, Py_ssize_t n) noexcept

    @cython.locals(fa=Py_ssize_t, fb=Py_ssize_t, na=Py_ssize_t, nb=Py_ssize_t, at=Py_ssize_t,
                   bt=Py_ssize_t, i=Py_ssize_t)
    cdef bint _draft_less(self, Py_ssize_t a, Py_ssize_t b) noexcept

    @cython.locals(i=Py_ssize_t, d=int, j=Py_ssize_t)
    cdef int _sort_drafts(self) noexcept

    @cython.locals(i=Py_ssize_t, h=double, c=double, axis=int, line=int, j=Py_ssize_t,
                   ph=double, pc=double, pa=int, pl=int)
    cdef int _sort_halves(self) noexcept

    @cython.locals(n=Py_ssize_t, r0=int, r1=int, c0=int, c1=int, d=Py_ssize_t, at=Py_ssize_t,
                   i=Py_ssize_t, cids=Py_ssize_t, a=int, b=int, pool="int[::1]", op=int,
                   m=Py_ssize_t, count=Py_ssize_t, centre=int, period=Py_ssize_t,
                   q=Py_ssize_t, same=bint, repeats=bint, rule_cost=double, heuristic=double,
                   f=Py_ssize_t)
    cdef int _draft(self, int axis, Py_ssize_t nb) except -9

    @cython.locals(nr=Py_ssize_t, nc=Py_ssize_t, m=Py_ssize_t, d=Py_ssize_t, rows=Py_ssize_t,
                   columns=Py_ssize_t, cids=Py_ssize_t, i=Py_ssize_t, j=Py_ssize_t,
                   k=Py_ssize_t, rule_cost=double, heuristic=double, f=Py_ssize_t)
    cdef int _grid(self, int n0, int n1) except -9

    @cython.locals(n=Py_ssize_t, r0=int, r1=int, c0=int, c1=int, full="int[::1]", i=Py_ssize_t,
                   run=Py_ssize_t, period=Py_ssize_t, j=Py_ssize_t, k=Py_ssize_t,
                   end=Py_ssize_t, nb=Py_ssize_t)
    cdef int _runs(self, int axis, Py_ssize_t nf) except -9

    @cython.locals(r0=int, r1=int, c0=int, c1=int, rep="int[::1]", spans=Py_ssize_t,
                   k=Py_ssize_t, at=Py_ssize_t, a=int, b=int, j=Py_ssize_t, x=int, y=int,
                   full="int[::1]", lo=int, hi=int, blocks=Py_ssize_t, free=bint,
                   nb=Py_ssize_t, i=Py_ssize_t, line=int)
    cdef int _repeated(self, int axis, Py_ssize_t nf) except -9

    @cython.locals(j=Py_ssize_t, k=Py_ssize_t)
    cdef Py_ssize_t _mark(self, Py_ssize_t n, int line) noexcept

    @cython.locals(r0=int, r1=int, c0=int, c1=int, lo=int, hi=int, same=bint, rule_cost=double,
                   heuristic=double, k=Py_ssize_t)
    cdef int _rank_in_two(self, int axis, int line) except -9

    @cython.locals(f=Py_ssize_t, at=Py_ssize_t, part="int[::1]", columns=Py_ssize_t,
                   across=Py_ssize_t)
    cdef long _part(self, Py_ssize_t d, Py_ssize_t i) noexcept

    @cython.locals(g=Py_ssize_t, axis=int, op=int, count=int, centre=int, bounds=Py_ssize_t,
                   n_bounds=Py_ssize_t, across=Py_ssize_t, n_across=Py_ssize_t,
                   cids=Py_ssize_t, m=Py_ssize_t, a=Py_ssize_t, f=Py_ssize_t, i=Py_ssize_t,
                   cid=int, label=int, order=Py_ssize_t, k=Py_ssize_t, cells=long,
                   j=Py_ssize_t, needs=Py_ssize_t, n_needs=Py_ssize_t, seen=bint,
                   form="int[::1]", n=Py_ssize_t, kids=Py_ssize_t, n_kids=Py_ssize_t, kid=int,
                   part="int[::1]")
    cdef int _keep(self, int e, Py_ssize_t d) except -9

    @cython.locals(x=Py_ssize_t, y=Py_ssize_t, i=int)
    cdef bint entry_less(self, int a, int b) noexcept

    @cython.locals(i=Py_ssize_t, up=Py_ssize_t)
    cdef int heap_push(self, int e) except -9

    @cython.locals(top=int, n=Py_ssize_t, last=int, i=Py_ssize_t, c=Py_ssize_t)
    cdef int heap_pop(self) noexcept

    @cython.locals(i=Py_ssize_t)
    cdef void clear_grammar(self) noexcept

    @cython.locals(first=int, n=int, low=double, total=double, i=int, at=Py_ssize_t, x=double,
                   lo=int, hi=int, mid=int, chosen=int, least=double, a=int, score=double,
                   stamp=int, needs=Py_ssize_t, j=int, need=int, value=double, cov=Py_ssize_t,
                   k=Py_ssize_t)
    cdef int choose(self, int e) except -9

    @cython.locals(e=int, cid=int, a=int, kids=Py_ssize_t, k=int, kid=int, sub=int)
    cdef int build(self, int start) except -9

    @cython.locals(a=int, p=Py_ssize_t, words=Py_ssize_t, base=Py_ssize_t, n=int,
                   parts=Py_ssize_t, s=Py_ssize_t, i=int, sub=int, below=Py_ssize_t,
                   w=Py_ssize_t, kind=Py_ssize_t)
    cdef int visit(self, int cid) except -9

    @cython.locals(n=Py_ssize_t, words=Py_ssize_t, i=Py_ssize_t, total=double, cid=int)
    cdef double survey(self) except? -1.0

    @cython.locals(n=Py_ssize_t, n_distinct=int, i=Py_ssize_t, c=double, g=int,
                   words=Py_ssize_t, members=Py_ssize_t, w=Py_ssize_t,
                   word="unsigned long long", low="unsigned long long", p=Py_ssize_t,
                   total=double, cid=int, at=Py_ssize_t, k=Py_ssize_t)
    cdef int learn(self) except -9

    @cython.locals(i=Py_ssize_t)
    cdef void forget_learned(self) noexcept

    @cython.locals(made=object, view="int[::1]", i=Py_ssize_t)
    cdef object _order_actions(self)
