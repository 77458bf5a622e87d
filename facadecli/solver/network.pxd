# The C types of network.py where Cython compiles it (setup.py); network.py stays plain
# Python and runs as it is where there is no C compiler. Only types here: no logic.
cimport cython


cdef object _DOUBLES, _INTS, _FLAGS
cdef double INF, NAN, SAME
cdef long long BIG
cdef int FREE, AFTER_EMPTY, AFTER_ATTACHED, LEAF_WORK, COMBINATION_WORK
cdef int NOT_NEAR
cdef int NO_OPAQUE, ATTACHED_GAP, NO_COVER, GAP_BEFORE_ATTACHED, COVERED

cdef object _doubles(Py_ssize_t n)
cdef object _ints(Py_ssize_t n)
cdef object _flags(Py_ssize_t n)
cdef double r9(double x) noexcept

@cython.locals(t=double, j=int)
cdef double dot(double[::1] a, double[::1] b, int n) noexcept


cdef class Move:
    cdef public int start, end
    cdef public double fixed
    cdef public int unsized, letters
    cdef public bint lead, opaque, transparent, unoccludable
    cdef public bint first_attached, last_attached, fixed_only
    cdef public int piece_of, tail
    cdef public double tail_size, low, high


cdef class Whole:
    cdef int count, unsized
    cdef double fixed
    cdef bint opaque, transparent, sized_only, unoccludable, first_attached, last_attached

    @cython.locals(size=double, attached=bint)
    cdef void add(self, Row row, int k) noexcept


cdef class Options:
    cdef list moves
    cdef double[::1] lens
    cdef int[::1] known, order
    cdef public int n
    cdef int n_whole, n_known


cdef class Row:
    cdef public int n
    cdef int[::1] var, segment, above, covering
    cdef double[::1] size, counts, rem
    cdef int[::1] rem_ph
    cdef int stride
    cdef signed char[::1] transparent, opaque, attached, unoccludable
    cdef double least
    cdef bint has_attached
    cdef list moves, cached
    cdef int n_above, n_covering

    @cython.locals(n=int, positions=int, met=int, k=int, v=int, least=double, j=int,
                   counts="double[::1]", p=int, rem="double[::1]", pairs="int[::1]",
                   before=int, index=object, number=int, times=int, stride=int, at=int,
                   made=object)
    cdef void read(self, letters, above, covering, dict variables, int count, int nv,
                   int sized) except *

    @cython.locals(m=Move, pieces=int)
    cdef void push_move(self, list moves, int start, int end, Whole held, int piece_of,
                        int tail) except *

    @cython.locals(held=Whole, segment=int, index=int, following=int)
    cdef void extend_moves(self, list moves, int start, int k, int transparent,
                           int piece_of) except *

    @cython.locals(found=list, made=list, k=int, transparent=int)
    cdef list moves_of(self, int position)

    @cython.locals(m=Move)
    cdef Move spanning(self, int start, int end)


cdef int _count(Options o) noexcept
cdef bint stands_aside(Move m) noexcept
cdef bint plain(Move m) noexcept


cdef class Group:
    cdef list rows
    cdef public int n
    cdef int[::1] ends


cdef class System:
    cdef int npiv, nb
    cdef int[::1] piv_var
    cdef double[::1] piv_row, piv_rhs, basis, brhs, point
    cdef double value
    cdef dict probes

    @cython.locals(made=object, buffer="double[::1]", at=Py_ssize_t)
    cdef void make(self, int nv, int sized, int npiv, int nb) except *


cdef class Cell:
    cdef public Cell prev
    cdef public int depth
    cdef public list column


cdef class Node:
    cdef int[::1] positions, memory, before, has_used
    cdef double[::1] x, used
    cdef System system
    cdef Cell path

    @cython.locals(made=object, numbers="int[::1]", lengths="double[::1]")
    cdef void make(self, int nv, int count) except *


cdef class Child:
    cdef Node node
    cdef double bound, spread
    cdef int index, empties, pieces, letters
    cdef long long key

    cpdef tuple order(self)


cdef class Search:
    cdef object __weakref__
    cdef int nv, sized
    cdef double[::1] target
    cdef double canvas
    cdef public double incumbent
    cdef long long limit
    cdef public long long used
    cdef double deadline
    cdef public bint timed_out
    cdef bint first_only, gaps, recording
    cdef long long combinations
    cdef int stop, progress
    cdef object leaf
    cdef dict rejected
    cdef list groups, done, builders
    cdef double[::1] row, known, width, shifted, reduced, coef, span, a, least, held, least_rhs
    cdef object diff
    cdef double[::1] diff_view
    cdef signed char[::1] has, fixed

    @cython.locals(before=cython.longlong)
    cdef int spend(self, long long units) except -1

    @cython.locals(nv=int, i=int, j=int, base=int, c=double, piv_row="double[::1]")
    cdef double reduce(self, System y, double[::1] row, double rhs) noexcept

    @cython.locals(sz=int, nb=int, i=int, j=int, base=int, t=double, ci=double,
                   basis="double[::1]", c="double[::1]")
    cdef double orthogonal(self, System y, double[::1] a, double rhs) noexcept

    @cython.locals(nv=int, sz=int, row="double[::1]", v=int, j=int, i=int, base=int,
                   most=double, z=System, pv=double, pivot_rhs=double, c=double,
                   norm=double, t=double, residual=double)
    cdef System system_add(self, System y, double[::1] given, double rhs, double scale)

    @cython.locals(value=double)
    cdef double probe(self, System y) except? -1.0

    @cython.locals(nv=int, sz=int, row="double[::1]", j=int, rhs=double, norm2=double,
                   residual=double)
    cdef double probe_of(self, System y, double[::1] given) noexcept

    @cython.locals(nv=int, sz=int, row="double[::1]", j=int, rhs=double)
    cdef bint implies_zero(self, System y, double[::1] given, int offset) noexcept

    @cython.locals(seen=list)
    cdef bint reject(self, int code, int g, int r, int a, Move m) except -1

    cpdef list rejections(self)

    @cython.locals(group=Group, first=int, any_opaque=bint, r=int, m=Move, row=Row,
                   covered=bint, i=int, o=Move)
    cdef bint valid(self, int g, list entries, int[::1] memory) except -1

    @cython.locals(group=Group, merged=list, r=int, a=Move, b=Move, joined=Move,
                   recording=bint, fits=bint, row=Row)
    cdef bint merges(self, int g, list last, list entries, int[::1] before) except -1

    @cython.locals(nv=int, first=int, last=int, j=int, counts="double[::1]")
    cdef void whole_into(self, Row row, Move m, double[::1] into, int at) noexcept

    @cython.locals(nv=int, used="double[::1]", base=int, j=int)
    cdef bint known_length(self, Row row, Move m, Node node, int r, double[::1] into,
                           int at) except -1

    @cython.locals(k=int)
    cdef bint holds_placeholder(self, double[::1] length, int at) noexcept

    @cython.locals(group=Group, row=Row, position=int, inside=bint, gaps=int,
                   cached=Options, o=Options, gap=bint, m=Move, at=int, i=int, nv=int,
                   moves=list, lens="double[::1]", known="int[::1]", order="int[::1]",
                   made=object)
    cdef Options options_of(self, int g, int r, Node node)

    @cython.locals(nv=int, sz=int, first="double[::1]", target="double[::1]",
                   d="double[::1]", shifted="double[::1]", reduced="double[::1]",
                   placeholders=bint, own=bint, k=int, use_shifted=bint, alone=double, fat=int,
                   norm=double, off=double, miss=double, residual=double, value=double,
                   y=System)
    cdef (int, double) fits(self, Builder b, double[::1] length, int at, bint pinned,
                            double rest) except *

    @cython.locals(key=Py_ssize_t, nv=int, sz=int, o=Options, mask="signed char[::1]",
                   at=int, limit=double, y=System, reduced="double[::1]",
                   pinned=bint, rest=double, k=int, least=double, ordered=bint,
                   order="int[::1]", nw=int, nk=int, u=int, w=int, fit=int, miss=double,
                   total=double, low=int, high=int, mid=int, start=int, fo=Options,
                   first="double[::1]", group=Group, row=Row, lens="double[::1]", fat=int)
    cdef int fitting(self, Builder b, int fr, int j, int r) except -1

    @cython.locals(r=int, o=Options, masked=bint, at=int, k=int, m=Move, held=bint)
    cdef int extend(self, Builder b, int i, int fr, int fj, bint solid) except -1

    @cython.locals(count=int, b=Builder, order="int[::1]", i=int, v=int, k=int,
                   stopped=int, columns=list)
    cdef list columns_of(self, int g, Node node, list opts)

    @cython.locals(group=Group, sz=int, nv=int, count=int, x="double[::1]",
                   target="double[::1]", least="double[::1]", least_rhs="double[::1]",
                   held="double[::1]", has="signed char[::1]", fixed="signed char[::1]",
                   v=int, i=int, j=int, r=int, k=int, p=int, base=int, nonzero=int,
                   row=Row, fine=bint, mine=double, theirs=double, best=double,
                   span="double[::1]", a="double[::1]", c="double[::1]",
                   point="double[::1]", basis="double[::1]", tol=double, most=double,
                   position=int, rem="double[::1]", pairs="int[::1]", times=int,
                   violation=double, t=double, ci=double, norm=double, value=double)
    cdef double bound_within(self, int g, System y, Node child) except? -1.0

    @cython.locals(k=int)
    cdef bint empty_piece(self, Row row, Move m, double[::1] used, int r,
                          System y) noexcept

    @cython.locals(group=Group, count=int, nv=int, wr=int, r=int, m=Move,
                   width="double[::1]", c=Node, used="double[::1]", j=int, y=System,
                   known="double[::1]", row=Row, base=int)
    cdef Node child_of(self, int g, Node node, list entries)

    @cython.locals(node=Node)
    cdef Node start_of(self, int g, System y)

    @cython.locals(paths=list, g=int, end=Cell, columns=list, cell=Cell, m=Move)
    cdef int call_leaf(self, Node node) except -1

    @cython.locals(closed=System)
    cdef int finish_group(self, int g, Node node) except -1

    @cython.locals(group=Group, count=int, at_end=bint, progress=int, r=int, opts=list,
                   children=list, entries=list, stretch=Move, c=Node, bound=double,
                   child=Child, lows=double, highs=double, m=Move, d=double, columns=list)
    cdef int dfs(self, int g, Node node) except -1

    @cython.locals(found=Move, r=int, m=Move)
    cdef Move stretch_of(self, list entries, int count)

    @cython.locals(nv=int, total="double[::1]", made=object, group=Group, r=int, row=Row,
                   j=int)
    cdef System filling(self, System y)

    @cython.locals(empty=System, j=int)
    cpdef int run(self, bint gaps) except -1


cdef class Builder:
    cdef int g, R, last
    cdef Node node
    cdef list opts, chosen, out
    cdef int[::1] order, base
    cdef dict fits
    cdef signed char[::1] masks
    cdef int size, filled
    cdef double[::1] first
    cdef int first_at
    cdef double limit, margin

    @cython.locals(total=int, r=int)
    cdef void start(self, Node node, list opts) except *

    cdef void done(self) noexcept

    @cython.locals(at=int, size=int, made=object, masks="signed char[::1]", k=int)
    cdef int reserve(self, int n) except -1


@cython.locals(m=Py_ssize_t, i=Py_ssize_t, names=list, values=list, users=list,
               konst="double[::1]", solved="signed char[::1]", acc="double[::1]",
               at="int[::1]", touched="int[::1]", left=double, count=int, v=int, c=double,
               ev=list, ec=list, j=Py_ssize_t, u=int, pivot=int, terms=int, best=double,
               size=double, a=double, xv=list, xc=list, constants=list, free=list,
               columns=int, entries=list, order=list)
cpdef object eliminate(rows, int n, double zero, double tolerance)

@cython.locals(ev=list, ec=list, xv=list, xc=list, k=Py_ssize_t, i=Py_ssize_t, c=double,
               last=Py_ssize_t, u=int, value=double, j=int, kept=Py_ssize_t)
cdef void _substitute(list names, list values, list users, double[::1] konst, int[::1] at,
                      int v, int p, double zero) except *
