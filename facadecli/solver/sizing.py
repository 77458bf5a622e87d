"""Sizing (Ilčík et al. 2015, section 5.3; SPEC 2.7): one quadratic program per axis.

Variables: one size per symbol on the axis (shared by every group), the width of every
column of every group, and one length per piece of a split transparent letter that shares
its entry with other letters (a piece alone in its entry is its column's width). Equalities:
the columns of a group fill the canvas; every non-empty entry is as wide as its column;
the pieces of a split letter add up to its symbol's size. Objective: the sum over sized
symbols of (size - preferred)^2, plus a tiny weight on everything else so that the
solution is unique (a placeholder covers as little as it can).

When no bound is active the optimum is the equality-constrained problem's, solved in
closed form: the equalities are eliminated one variable at a time (sparse: an entry's row
holds a few letters), which leaves the few free lengths the layout really has, and the
objective over those is a small linear system. Otherwise ``solve`` is the cvxpy QP with every
bound, and ``search_solve`` calls Clarabel directly for the searches' many small QPs.
"""

from __future__ import annotations

import functools
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from facadecli import native
from facadecli.solver.alignment import Alignment, Move
from facadecli.spec.model import Spec

if TYPE_CHECKING:
    from facadecli.solver import network
else:  # compiled where it was built from this very source, else interpreted
    network = native.load(native.EXACT_SEARCH)

TINY = 1e-8  # weight of unsized variables: breaks ties, never trades against a deviation
MIN_SIZE = 1e-3  # every sized letter is at least a millimetre long
ZERO = 1e-12  # coefficients smaller than this are rounding left by an elimination


class Piece(NamedTuple):
    """Where a piece of a split letter sits: group, row, letter index, column (a named
    tuple: a long façade's programs key thousands of them)."""

    group: str
    row: int
    letter: int
    column: int


def entry_parts(move: Move) -> tuple[list[int], list[int]]:
    """(whole letters, letters of which the entry holds a piece) of a non-empty entry."""
    if move.start == move.end:
        return [], [move.start // 2]
    first, last = move.start // 2, move.end // 2
    pieces = []
    whole_from = first
    if move.start % 2:
        pieces.append(first)
        whole_from = first + 1
    if move.end % 2:
        pieces.append(last)
    return list(range(whole_from, last)), pieces


@dataclass
class Program:
    """The sizing problem of one axis as matrices: minimise sum w (z - t)^2, E z = d."""

    names: list[str]  # one per variable, for messages
    target: np.ndarray
    weight: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    rhs: np.ndarray
    rows: list[tuple[dict[int, float], float]]  # the equalities, sparse: coefficients, rhs
    symbols: dict[str, int]
    columns: dict[tuple[str, int], int]
    pieces: dict[Piece, int]
    sized: list[int]  # variables whose deviation is the objective

    @functools.cached_property
    def _triplets(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The equalities' nonzero coefficients: (row, variable, coefficient) arrays."""
        at = [(i, j, c) for i, (terms, _) in enumerate(self.rows) for j, c in terms.items()]
        row, column, value = zip(*at, strict=True) if at else ((), (), ())
        return np.array(row, dtype=int), np.array(column, dtype=int), np.array(value, dtype=float)

    @functools.cached_property
    def parametrized(self) -> tuple[np.ndarray, np.ndarray] | None:
        """Every solution of the equalities as ``z0 + N y`` (:func:`_parametrized`), found
        once for the closed form and the solve on a line."""
        return _parametrized(self.rows, len(self.names))

    def residual(self, z: np.ndarray) -> float:
        """The largest amount by which ``z`` misses an equality."""
        row, column, value = self._triplets
        made = np.bincount(row, weights=value * z[column], minlength=len(self.rows))
        return float(np.abs(made - self.rhs).max(initial=0.0))


def build_program(spec: Spec, groups: Mapping[str, Alignment], canvas: float) -> Program:
    names: list[str] = []
    target: list[float] = []
    weight: list[float] = []
    lower: list[float] = []
    upper: list[float] = []
    symbols: dict[str, int] = {}
    columns: dict[tuple[str, int], int] = {}
    pieces: dict[Piece, int] = {}
    sized: list[int] = []

    def variable(name: str, goal: float, w: float, low: float, high: float) -> int:
        names.append(name)
        target.append(goal)
        weight.append(w)
        lower.append(low)
        upper.append(high)
        return len(names) - 1

    def symbol(name: str) -> int:
        if name not in symbols:
            declared = spec.symbols.get(name)
            size = declared.size if declared else None
            if size is None:
                symbols[name] = variable(f"size of {name}", 0.0, TINY, 0.0, np.inf)
            else:
                low = max(MIN_SIZE, declared.min or 0.0) if declared else MIN_SIZE
                high = declared.max if declared and declared.max is not None else np.inf
                symbols[name] = variable(f"size of {name}", size, 1.0, low, high)
                sized.append(symbols[name])
        return symbols[name]

    rows: list[tuple[dict[int, float], float]] = []  # sparse equality rows
    seen: set[tuple[tuple[int, float], ...]] = set()
    for group, alignment in sorted(groups.items()):
        for j in range(alignment.columns):
            columns[(group, j)] = variable(f"column {j} of group {group}", 0.0, TINY, 0.0, np.inf)
        rows.append(({columns[(group, j)]: 1.0 for j in range(alignment.columns)}, canvas))
        split: dict[tuple[int, int], list[int]] = {}
        words = [row.word for row in alignment.rows]
        letter_symbol: list[list[int | None]] = [[None] * len(word) for word in words]
        for j, entries in enumerate(alignment.entries):
            column = columns[(group, j)]
            first: dict[int, float] | None = None
            first_letters: dict[int, float] | None = None  # its symbols, if it holds no piece
            for r, move in enumerate(entries):
                if move is None:
                    continue
                whole, parts = entry_parts(move)
                if not whole and len(parts) == 1:
                    # a piece alone is as long as its column: the column stands for it
                    # (with the piece's tiny weight added, so the objective is the same)
                    pieces[Piece(group, r, parts[0], j)] = column
                    weight[column] += TINY
                    split.setdefault((r, parts[0]), []).append(column)
                    continue
                coefficients: dict[int, float] = {column: -1.0}
                letters: dict[int, float] = {}
                known = letter_symbol[r]
                for k in whole:
                    index = known[k]
                    if index is None:
                        index = known[k] = symbol(words[r][k].symbol)
                    letters[index] = letters.get(index, 0.0) + 1.0
                coefficients.update(letters)
                for k in parts:
                    index = pieces[Piece(group, r, k, j)] = variable(
                        f"piece of {words[r][k].symbol}", 0.0, TINY, 0.0, np.inf
                    )
                    coefficients[index] = 1.0
                    split.setdefault((r, k), []).append(index)
                if first is None:
                    first = coefficients
                    first_letters = None if parts else letters
                    rows.append((coefficients, 0.0))
                    continue
                if not parts and letters == first_letters:
                    continue  # the same letters as the first: nothing new
                # the entry as long as the column's first, written without the column: a
                # long façade's many equal columns then give one row ("W == Sp"), not
                # one a column and row (the same equalities: the solution is the same)
                same = _difference(coefficients, first)
                if parts:
                    rows.append((dict(same), 0.0))  # a new piece: a new row
                elif same and same not in seen:
                    seen.add(same)
                    rows.append((dict(same), 0.0))
        for (r, k), parts in split.items():
            coefficients = dict.fromkeys(parts, 1.0)
            index = symbol(words[r][k].symbol)
            coefficients[index] = coefficients.get(index, 0.0) - 1.0
            rows.append((coefficients, 0.0))
    return Program(
        names=names,
        target=np.array(target),
        weight=np.array(weight),
        lower=np.array(lower),
        upper=np.array(upper),
        rhs=np.array([value for _, value in rows]),
        rows=rows,
        symbols=symbols,
        columns=columns,
        pieces=pieces,
        sized=sized,
    )


# what a program is made of: the canvas, and each group's name, rows and entries
AlignedKey = tuple[float, tuple[tuple[str, tuple[object, ...], tuple[object, ...]], ...]]
Sized = dict[AlignedKey, tuple[Program, "Sizing | None"]]


def sized_alignments(
    spec: Spec, groups: Mapping[str, Alignment], canvas: float, known: Sized | None = None
) -> tuple[Program, Sizing | None]:
    """The alignments' program (:func:`build_program`) and its optimum
    (:func:`search_solve`); remembered in ``known`` (one spec's: the caller keeps it for
    one axis solve) by what the program is made of, each group's rows and entries and the
    canvas, so that constructions laid from other sizes that cut the rows into the same
    columns are sized once. The same program, so the same answer."""
    if known is None:
        program = build_program(spec, groups, canvas)
        return program, search_solve(program)
    key = (canvas, tuple((name, a.rows, a.entries) for name, a in sorted(groups.items())))
    found = known.get(key)
    if found is None:
        program = build_program(spec, groups, canvas)
        found = known[key] = (program, search_solve(program))
    return found


def _difference(a: Mapping[int, float], b: Mapping[int, float]) -> tuple[tuple[int, float], ...]:
    """The row ``a - b``: its nonzero coefficients, by variable."""
    merged = dict(a)
    for j, value in b.items():
        merged[j] = merged.get(j, 0.0) - value
    return tuple(sorted((j, value) for j, value in merged.items() if value != 0.0))


@dataclass(frozen=True)
class Sizing:
    values: np.ndarray
    objective: float  # sum of squared deviations of sized symbols
    coverage: float  # total size of unsized (placeholder) symbols

    def of(self, index: int) -> float:
        return float(self.values[index])


def _result(program: Program, values: np.ndarray) -> Sizing:
    deviation = values[program.sized] - program.target[program.sized]
    unsized = [i for i in program.symbols.values() if i not in set(program.sized)]
    return Sizing(values, float(deviation @ deviation), float(values[unsized].sum()))


def _equality_solution(program: Program) -> tuple[np.ndarray, bool]:
    """The minimiser under the equalities alone (bounds ignored), in closed form, and
    whether the equalities hold: they are eliminated (:func:`_parametrized`), leaving
    ``z = z0 + N y`` over the free lengths ``y``, and the objective over ``y`` is the
    small positive definite system ``(N^T W N) y = N^T W (t - z0)``."""
    parametrized = program.parametrized
    if parametrized is None:  # the equalities contradict each other
        return program.target.copy(), False
    z0, free = parametrized
    w = program.weight
    if free.shape[1]:
        weighted = free.T * w
        y = np.linalg.solve(weighted @ free, weighted @ (program.target - z0))
        z = z0 + free @ y
    else:
        z = z0
    scale = max(1.0, float(np.abs(program.rhs).max(initial=0.0)))
    return z, program.residual(z) <= 1e-9 * scale


def _parametrized(
    rows: Sequence[tuple[Mapping[int, float], float]], n: int
) -> tuple[np.ndarray, np.ndarray] | None:
    """Every solution of the sparse equalities ``rows`` over ``n`` variables as
    ``z0 + N y`` (``y`` the free variables), or None when they contradict each other
    (the elimination is :func:`facadecli.solver.network.eliminate`)."""
    scale = max((abs(rhs) for _, rhs in rows), default=0.0)
    found = network.eliminate(rows, n, ZERO, 1e-9 * max(1.0, scale))
    if found is None:
        return None
    constants, free, entries = found
    basis = np.zeros((n, len(free)))
    basis[free, np.arange(len(free))] = 1.0
    if entries:
        v, j, c = zip(*entries, strict=True)
        basis[list(v), list(j)] = c
    return np.array(constants), basis


def _closed_form(program: Program) -> Sizing | np.ndarray:
    """The optimum in closed form when it meets every equality and bound (then no bound is
    active and it is the QP's optimum); else the equality solution (a QP solver must
    decide, and says when nothing is feasible)."""
    z, meets = _equality_solution(program)
    if meets and (z >= program.lower - 1e-9).all() and (z <= program.upper + 1e-9).all():
        return _result(program, np.clip(z, program.lower, program.upper))
    return z


def exact(program: Program) -> Sizing | None:
    """The QP's optimum: the closed form when no bound is active, else the QP in cvxpy;
    None if infeasible."""
    found = _closed_form(program)
    return solve(program) if isinstance(found, np.ndarray) else found


_MANY_FREE = object()  # _on_a_line(): more than one free length, a QP solver must decide


def _on_a_line(program: Program) -> Sizing | object | None:
    """The QP's optimum when the equalities leave at most one free length ``y``, without a
    solver: the solutions are the line ``z0 + a y``, every bound cuts it to an interval of
    ``y``, and the objective is a parabola in ``y``, least at its vertex clamped to the
    intervals' intersection; None when that is empty (infeasible), :data:`_MANY_FREE` when
    the layout has more free lengths."""
    parametrized = program.parametrized
    if parametrized is None:
        return None  # the equalities contradict each other
    z0, free = parametrized
    if free.shape[1] > 1:
        return _MANY_FREE
    low, high = -np.inf, np.inf
    if free.shape[1]:
        a = free[:, 0]
        moving = np.abs(a) > ZERO
        ends = np.stack(
            [(program.lower - z0)[moving] / a[moving], (program.upper - z0)[moving] / a[moving]]
        )
        low = float(ends.min(axis=0).max(initial=-np.inf))
        high = float(ends.max(axis=0).min(initial=np.inf))
        weighted = a * program.weight
        y = float(weighted @ (program.target - z0)) / float(weighted @ a)
        z = z0 + a * min(max(y, low), high)
    else:
        z = z0
    if (z < program.lower - 1e-9).any() or (z > program.upper + 1e-9).any():
        return None  # the interval is empty, or a fixed length breaks a bound
    scale = max(1.0, float(np.abs(program.rhs).max(initial=0.0)))
    if program.residual(z) > 1e-9 * scale:
        return None
    return _result(program, np.clip(z, program.lower, program.upper))


def search_solve(program: Program) -> Sizing | None:
    """The QP with all bounds, for the searches' many small layouts: the closed form when
    no bound is active; exactly on a line when the equalities leave at most one free
    length; else Clarabel called directly (the solver cvxpy calls, without cvxpy's compile
    step of ~10 ms); None if infeasible."""
    found = _closed_form(program)
    if not isinstance(found, np.ndarray):
        return found
    on_line = _on_a_line(program)
    if on_line is not _MANY_FREE:
        return on_line  # type: ignore[return-value]
    if _bounds_contradict(program):
        return None
    return _clarabel(program)


def _bounds_contradict(program: Program, rounds: int = 12) -> bool:
    """Whether the bounds cannot all hold on the solutions ``z0 + N y`` of the equalities,
    shown by propagating intervals: each bound ``lower <= z0 + N y <= upper`` narrows every
    free length ``y_j`` to what the others' intervals leave it, round after round. A proof,
    not a guess (an empty interval means no solution; a margin of ``1e-7`` of the program's
    scale keeps rounding from proving anything), and cheap: most layouts the searches size
    with several free lengths are infeasible, and this shows it without a QP solver. When
    it shows nothing, the QP solver decides."""
    parametrized = program.parametrized
    if parametrized is None:
        return True  # the equalities contradict each other
    z0, free = parametrized
    moving = np.abs(free) > ZERO
    bounded = moving.any(axis=1) & (np.isfinite(program.lower) | np.isfinite(program.upper))
    a = np.where(moving, free, 0.0)[bounded]
    below, above = (program.lower - z0)[bounded], (program.upper - z0)[bounded]
    low, high = np.full(free.shape[1], -np.inf), np.full(free.shape[1], np.inf)
    margin = 1e-7 * max(1.0, float(np.abs(program.rhs).max(initial=0.0)))
    with np.errstate(invalid="ignore"):  # 0 x inf: a length a bound does not involve
        for _ in range(rounds):
            ends = np.stack([a * low, a * high])
            ends[:, ~moving[bounded]] = 0.0
            least, most = ends.min(axis=0), ends.max(axis=0)
            # what the other lengths of a bound's row can add, least and most
            others_least = _sum_but_one(least, -np.inf)
            others_most = _sum_but_one(most, np.inf)
            span_low = (below[:, None] - others_most) / np.where(moving[bounded], a, np.nan)
            span_high = (above[:, None] - others_least) / np.where(moving[bounded], a, np.nan)
            flipped = a < 0
            new_low = np.where(flipped, span_high, span_low)
            new_high = np.where(flipped, span_low, span_high)
            narrowed_low = np.fmax(low, np.nanmax(new_low, axis=0, initial=-np.inf))
            narrowed_high = np.fmin(high, np.nanmin(new_high, axis=0, initial=np.inf))
            if (narrowed_low > narrowed_high + margin).any():
                return True
            if np.array_equal(narrowed_low, low) and np.array_equal(narrowed_high, high):
                return False
            low, high = narrowed_low, narrowed_high
    return False


def _sum_but_one(terms: np.ndarray, infinite: float) -> np.ndarray:
    """Per entry of each row, the sum of the row's other entries (infinite if another is)."""
    finite = np.isfinite(terms)
    total = np.where(finite, terms, 0.0).sum(axis=1, keepdims=True)
    count = (~finite).sum(axis=1, keepdims=True)
    but_one = total - np.where(finite, terms, 0.0)
    others_infinite = count - (~finite) > 0
    return np.where(others_infinite, infinite, but_one)


def _clarabel(program: Program) -> Sizing | None:
    """The QP with all bounds, by Clarabel; None if infeasible."""
    import clarabel

    n = len(program.names)
    low = np.flatnonzero(np.isfinite(program.lower))
    high = np.flatnonzero(np.isfinite(program.upper))
    cones = [clarabel.ZeroConeT(len(program.rows))]
    if low.size + high.size:
        cones.append(clarabel.NonnegativeConeT(int(low.size + high.size)))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    everything = np.arange(n)
    hessian = _csc(everything, everything, 2.0 * program.weight, (n, n))
    linear = -2.0 * program.weight * program.target
    rhs = np.concatenate([program.rhs, -program.lower[low], program.upper[high]])
    constraints = _constraints(program, low, high)
    solution = clarabel.DefaultSolver(hessian, linear, constraints, rhs, cones, settings).solve()
    if solution.status not in (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved):
        return None
    values = np.clip(np.asarray(solution.x, dtype=float), program.lower, program.upper)
    if program.residual(values) > 1e-6:
        return None
    return _result(program, values)


def _constraints(program: Program, low: np.ndarray, high: np.ndarray) -> _Csc:
    """Clarabel's constraint matrix: the equalities, then one row a bound, ``-z >= -lower``
    for the variables ``low`` and ``z <= upper`` for ``high``."""
    row, column, value = program._triplets
    m = len(program.rows)
    return _csc(
        np.concatenate([row, m + np.arange(low.size), m + low.size + np.arange(high.size)]),
        np.concatenate([column, low, high]),
        np.concatenate([value, np.full(low.size, -1.0), np.ones(high.size)]),
        (m + int(low.size + high.size), len(program.names)),
    )


@dataclass(frozen=True)
class _Csc:
    """A sparse matrix in compressed columns, as Clarabel reads one: the attributes of a
    SciPy ``csc_matrix`` it takes (its values by column, their rows, where each column
    starts), without SciPy: ``scipy.sparse`` takes longer to import (some 90 ms of CPU)
    than a small façade takes to solve. Always canonical: rows sorted, no duplicates."""

    data: np.ndarray
    indices: np.ndarray
    indptr: np.ndarray
    shape: tuple[int, int]
    format: str = "csc"
    has_canonical_format: bool = True

    @property
    def nnz(self) -> int:
        return int(self.data.size)


def _csc(row: np.ndarray, column: np.ndarray, value: np.ndarray, shape: tuple[int, int]) -> _Csc:
    """The matrix of the given nonzeros (``row``, ``column``, ``value``; each place at most
    once) in compressed columns, what Clarabel takes: sorted by column, then row, and
    explicit zeros left out, as a dense matrix's nonzeros would be. Made from the nonzeros
    alone: a long façade's program has thousands of variables, and a dense matrix of its
    equalities and bounds (tens of millions of entries) took most of a solve's CPU."""
    kept = value != 0.0
    row, column, value = row[kept], column[kept], value[kept]
    order = np.lexsort((row, column))  # column by column, rows in order: canonical CSC
    starts = np.zeros(shape[1] + 1, dtype=np.int64)
    np.cumsum(np.bincount(column, minlength=shape[1]), out=starts[1:])
    return _Csc(
        np.ascontiguousarray(value[order], dtype=float),
        row[order].astype(np.int64),
        starts,
        (int(shape[0]), int(shape[1])),
    )


def solve(program: Program) -> Sizing | None:
    """The QP with all bounds, in cvxpy; None if infeasible."""
    import cvxpy as cp  # imported here: it takes half a second, and only sizing needs it
    import scipy.sparse as sparse

    n = len(program.names)
    z = cp.Variable(n)
    root = np.sqrt(program.weight)
    objective = cp.Minimize(cp.sum_squares(cp.multiply(root, z - program.target)))
    row, column, value = program._triplets
    kept = value != 0.0  # as a dense matrix's nonzeros: no explicit zeros, rows sorted
    equalities = sparse.csr_matrix(
        (value[kept], (row[kept], column[kept])), shape=(len(program.rows), n)
    )
    equalities.sort_indices()
    constraints = [equalities @ z == program.rhs]
    finite_low = np.isfinite(program.lower)
    finite_high = np.isfinite(program.upper)
    if finite_low.any():
        constraints.append(z[np.flatnonzero(finite_low)] >= program.lower[finite_low])
    if finite_high.any():
        constraints.append(z[np.flatnonzero(finite_high)] <= program.upper[finite_high])
    problem = cp.Problem(objective, constraints)
    try:
        with warnings.catch_warnings():  # "may be inaccurate": accepted, the layout is checked
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(solver=cp.CLARABEL)
    except cp.error.SolverError:
        return None
    if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or z.value is None:
        return None
    values = np.clip(np.asarray(z.value, dtype=float), program.lower, program.upper)
    return _result(program, values)


def explain_infeasible(program: Program) -> str:
    """A short reason for an infeasible sizing: the bounds that cannot all hold."""
    bounded = [
        program.names[i]
        for i in range(len(program.names))
        if np.isfinite(program.upper[i]) or program.lower[i] > 1e-3 + 1e-12
    ]
    if bounded:
        return "the min/max bounds of " + ", ".join(bounded[:6]) + " cannot all hold"
    return "the aligned columns cannot fill the canvas"


def column_starts(sizing: Sizing, program: Program, group: str, count: int) -> Sequence[float]:
    """Boundaries of a group's columns: 0, then the running sum of their widths."""
    bounds = [0.0]
    for j in range(count):
        bounds.append(bounds[-1] + sizing.of(program.columns[(group, j)]))
    return bounds
