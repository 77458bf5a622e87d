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

@cython.locals(d=tuple)
cdef bint _has_draft(list drafts, int axis, tuple bounds) except -1

@cython.locals(i=Py_ssize_t, total=double)
cdef double _lines_cost(list cost_of_line, int lo, tuple bounds) except? -1.0


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

    @cython.locals(at=Py_ssize_t, r0=int, r1=int, c0=int, c1=int, drafts=list, first=Py_ssize_t,
                   draft=tuple)
    cdef int provide(self, int e) except -9

    @cython.locals(region=tuple, lines=list, usable=list, fallback=list, least=list, cols1=int,
                   cols2=int, axis=int, found=list, crosses=list, i=int, at=Py_ssize_t,
                   clean=list, inside=list, costs=list, drafts=list, halves=list, lo=int, hi=int,
                   cost=list, full=tuple, n=Py_ssize_t, cheap=list, bounds=tuple, take=Py_ssize_t)
    cdef list drafts(self, int r0, int r1, int c0, int c1)

    @cython.locals(first=int, last=int, found=list, k=int, at=Py_ssize_t)
    cdef list _inside(self, int r0, int r1, int c0, int c1)

    @cython.locals(a=int, b=int, mid=int)
    cdef int _first_repeat_from(self, int row) noexcept

    @cython.locals(r0=int, r1=int, c0=int, c1=int, lo=int, hi=int, size=Py_ssize_t, cost=list,
                   pos=list, neg=list, k=int, at=Py_ssize_t, start=int, stop=int, cells=double,
                   total=double, i=Py_ssize_t, c=double)
    cdef list _line_costs(self, tuple region, int axis, list inside)

    @cython.locals(n=Py_ssize_t, r0=int, r1=int, c0=int, c1=int, cids=list, i=Py_ssize_t,
                   period=Py_ssize_t, run=list, j=Py_ssize_t, k=Py_ssize_t, end=Py_ssize_t,
                   bounds=tuple)
    cdef int _runs(self, list drafts, tuple region, list cost_of_line, int axis,
                   tuple full) except -9

    @cython.locals(r0=int, r1=int, c0=int, c1=int, spans=list, k=int, at=Py_ssize_t,
                   blocks=list, free=bint, marks=set, bounds=tuple)
    cdef int _repeated(self, list drafts, tuple region, list cost_of_line, int axis,
                       tuple full, list inside) except -9

    @cython.locals(lo=int, line=int, hi=int, same=bint, r0=int, r1=int, c0=int, c1=int,
                   rule_cost=double, heuristic=double)
    cdef tuple _rank_in_two(self, tuple region, list cost_of_line, int axis, tuple bounds)

    @cython.locals(n=Py_ssize_t, r0=int, r1=int, c0=int, c1=int, parts=list, cids=list, i=Py_ssize_t,
                   a=int, b=int, op=int, m=Py_ssize_t, count=Py_ssize_t, repeats=bint, centre=int, period=Py_ssize_t,
                   q=Py_ssize_t, same=bint, rule_cost=double, heuristic=double)
    cdef int _draft(self, list drafts, tuple region, list cost_of_line, int axis,
                    tuple bounds) except -9

    @cython.locals(heuristic=double, cost=double, axis=int, bounds=tuple, op=int, count=int,
                   centre=int, across=tuple, parts=list, cids=list, m=Py_ssize_t,
                   n_bounds=Py_ssize_t, n_across=Py_ssize_t, a=Py_ssize_t, f=Py_ssize_t,
                   i=Py_ssize_t, cid=int, label=int, order=Py_ssize_t, k=Py_ssize_t,
                   part=tuple, other=tuple, cells=long, j=Py_ssize_t, needs=Py_ssize_t,
                   n_needs=Py_ssize_t, seen=bint, form="int[::1]", n=Py_ssize_t,
                   kids=Py_ssize_t, n_kids=Py_ssize_t, kid=int)
    cdef int _keep(self, int e, tuple draft) except -9

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
