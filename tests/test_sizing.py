"""The sizing's closed form: the equalities eliminated into the free lengths, checked
against dense linear algebra on random systems."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from facadecli.solver import sizing


def random_system(seed: int, rows: int, variables: int) -> tuple[np.ndarray, np.ndarray]:
    """Sparse integer equalities with a solution, some rows repeated or summed (dependent),
    as a façade's are (an entry as long as its column, the same letters in many columns)."""
    rng = np.random.default_rng(seed)
    e = np.zeros((rows, variables))
    for row in e:
        picked = rng.choice(variables, size=rng.integers(1, 5), replace=False)
        row[picked] = rng.choice([-1.0, 1.0, 2.0], size=len(picked))
    dependent = rng.choice(rows, size=(rows // 4, 2))
    e = np.vstack([e, *(e[a] + e[b] for a, b in dependent)])
    z = rng.uniform(0.5, 3.0, variables)
    return e, e @ z


def sparse(e: np.ndarray, d: np.ndarray) -> list[tuple[dict[int, float], float]]:
    return [
        ({int(j): float(row[j]) for j in np.flatnonzero(row)}, float(rhs))
        for row, rhs in zip(e, d, strict=True)
    ]


def program(e: np.ndarray, d: np.ndarray, weight: np.ndarray, target: np.ndarray) -> sizing.Program:
    n = e.shape[1]
    return sizing.Program(
        names=[f"z{i}" for i in range(n)],
        target=target,
        weight=weight,
        lower=np.full(n, -np.inf),
        upper=np.full(n, np.inf),
        rhs=d,
        rows=sparse(e, d),
        symbols={},
        columns={},
        pieces={},
        sized=[i for i in range(n) if weight[i] == 1.0],
    )


@pytest.mark.parametrize("seed", range(12))
def test_every_solution_of_the_equalities_is_parametrized(seed: int) -> None:
    e, d = random_system(seed, rows=20 + seed, variables=30)
    found = sizing._parametrized(sparse(e, d), e.shape[1])
    assert found is not None
    z0, basis = found
    assert basis.shape[1] == e.shape[1] - np.linalg.matrix_rank(e)  # as free as it is
    for y in np.random.default_rng(seed).normal(size=(5, basis.shape[1])):
        assert e @ (z0 + basis @ y) == pytest.approx(d, abs=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_equalities_that_contradict_each_other_have_no_parametrization(seed: int) -> None:
    e, d = random_system(seed, rows=20, variables=30)
    e = np.vstack([e, e[3] + e[7]])
    d = np.append(d, d[3] + d[7] + 0.5)  # the sum of two rows, off by half a metre
    assert sizing._parametrized(sparse(e, d), e.shape[1]) is None


@pytest.mark.parametrize("seed", range(12))
def test_the_closed_form_is_the_weighted_least_squares_optimum(seed: int) -> None:
    """The minimiser of sum w (z - t)^2 under E z = d, with the solver's two weights (a
    sized symbol 1, a column or placeholder TINY), equals the dense KKT system's."""
    e, d = random_system(seed, rows=15, variables=30)
    rng = np.random.default_rng(seed + 100)
    weight = np.where(rng.random(30) < 0.5, 1.0, sizing.TINY)
    target = np.where(weight == 1.0, rng.uniform(0.5, 3.0, 30), 0.0)
    z, meets = sizing._equality_solution(program(e, d, weight, target))
    assert meets
    particular = np.linalg.lstsq(e, d, rcond=None)[0]
    free = scipy.linalg.null_space(e)  # an SVD: no elimination
    weighted = free.T * weight
    y = np.linalg.solve(weighted @ free, weighted @ (target - particular))
    assert z == pytest.approx(particular + free @ y, abs=1e-6)


@pytest.mark.parametrize("seed", range(12))
def test_the_elimination_finds_a_contradiction_exactly_when_the_ranks_differ(seed: int) -> None:
    """The equalities contradict each other exactly when ``[E | d]`` has a greater rank
    than ``E`` (dense linear algebra, no elimination); else every solution is found."""
    e, d = random_system(seed, rows=10 + 2 * seed, variables=30)
    if seed % 3 == 0:  # some contradict themselves
        e = np.vstack([e, e[1] + e[2]])
        d = np.append(d, d[1] + d[2] + 0.25)
    found = sizing._parametrized(sparse(e, d), e.shape[1])
    consistent = np.linalg.matrix_rank(np.column_stack([e, d])) == np.linalg.matrix_rank(e)
    assert (found is not None) == consistent
    if found is not None:
        z0, basis = found
        assert basis.shape[1] == e.shape[1] - np.linalg.matrix_rank(e)
        assert e @ z0 == pytest.approx(d, abs=1e-9)


def test_the_elimination_refuses_rows_it_cannot_read() -> None:
    with pytest.raises(IndexError):
        sizing._parametrized([({5: 1.0}, 0.0)], 3)
    with pytest.raises(TypeError):
        sizing._parametrized([([1.0], 0.0)], 3)  # type: ignore[list-item]


@pytest.mark.parametrize("seed", range(16))
def test_a_layout_with_one_free_length_is_sized_as_the_qp_solver_sizes_it(seed: int) -> None:
    """With one free length the bounds cut the solutions to an interval and the searches
    size the layout without a solver: the same optimum as Clarabel's, and the same
    verdict when the bounds leave nothing (about half of these)."""
    rng = np.random.default_rng(seed)
    n = 8
    while True:
        e, d = random_system(seed, rows=n, variables=n)
        e, d = e[: n - 1], d[: n - 1]
        if np.linalg.matrix_rank(e) == n - 1:
            break
        seed += 1000
    weight = np.where(rng.random(n) < 0.6, 1.0, sizing.TINY)
    target = np.where(weight == 1.0, rng.uniform(0.5, 3.0, n), 0.0)
    p = program(e, d, weight, target)
    p.lower = np.where(rng.random(n) < 0.7, rng.uniform(-1.0, 1.5, n), -np.inf)
    base = np.where(np.isfinite(p.lower), p.lower, 0.0)
    p.upper = np.where(rng.random(n) < 0.3, base + rng.uniform(0.5, 4.0, n), np.inf)
    p.sized = [i for i in range(n) if weight[i] == 1.0]
    line = sizing._on_a_line(p)
    solver = sizing._clarabel(p)
    if solver is None:
        assert line is None
        return
    assert isinstance(line, sizing.Sizing)
    assert line.objective == pytest.approx(solver.objective, abs=1e-6)
    assert line.values == pytest.approx(solver.values, abs=1e-5)


def test_a_layout_with_two_free_lengths_is_left_to_the_qp_solver() -> None:
    e, d = random_system(3, rows=4, variables=6)
    e, d = e[:4], d[:4]
    assert np.linalg.matrix_rank(e) == 4
    weight = np.ones(6)
    assert sizing._on_a_line(program(e, d, weight, np.ones(6))) is sizing._MANY_FREE


# -- bounds that contradict the equalities, shown without a QP solver --------------------
def bounded(e: np.ndarray, d: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> sizing.Program:
    made = program(e, d, np.ones(e.shape[1]), np.ones(e.shape[1]))
    made.lower, made.upper = lower, upper
    return made


def test_two_free_lengths_that_cannot_fill_their_sum_are_infeasible() -> None:
    """a + b = 10 with a, b at most 3 (and c free): no layout; lowering the sum to 6
    makes it feasible, and the propagation must not claim otherwise."""
    e = np.array([[1.0, 1.0, 0.0]])
    inf = np.inf
    lower, upper = np.array([0.0, 0.0, -inf]), np.array([3.0, 3.0, inf])
    assert sizing._bounds_contradict(bounded(e, np.array([10.0]), lower, upper))
    assert sizing.search_solve(bounded(e, np.array([10.0]), lower, upper)) is None
    assert not sizing._bounds_contradict(bounded(e, np.array([6.0]), lower, upper))
    assert sizing.search_solve(bounded(e, np.array([6.0]), lower, upper)) is not None


def test_contradicting_bounds_are_only_claimed_where_the_qp_finds_no_layout() -> None:
    """On random systems with random bounds around a solution (some kept, some pushed
    past it), every program the propagation calls infeasible Clarabel finds infeasible
    too. The family mixes feasible and infeasible programs, and the propagation does call
    some infeasible (it is not a test that cannot fail)."""
    claimed, feasible = 0, 0
    for seed in range(40):
        rng = np.random.default_rng(seed)
        e, d = random_system(seed, rows=8 + seed % 5, variables=12)
        solution = np.linalg.lstsq(e, d, rcond=None)[0]
        for trial in range(6):
            slack = rng.uniform(-0.1, 0.6, size=(2, 12))  # below 0: the solution cut off
            lower = np.where(rng.random(12) < 0.6, solution - slack[0], -np.inf)
            upper = np.where(rng.random(12) < 0.6, solution + slack[1], np.inf)
            made = bounded(e, d, lower, np.maximum(upper, lower))
            sized = sizing._clarabel(made)
            feasible += sized is not None
            if sizing._bounds_contradict(made):
                claimed += 1
                assert sized is None, (seed, trial)
    assert claimed >= 20 and feasible >= 40, (claimed, feasible)


# -- Clarabel's matrices, made from the nonzeros alone -----------------------------------
def _dense(matrix: sizing._Csc) -> np.ndarray:
    made = np.zeros(matrix.shape)
    for j in range(matrix.shape[1]):
        cut = slice(matrix.indptr[j], matrix.indptr[j + 1])
        made[matrix.indices[cut], j] = matrix.data[cut]
    return made


@pytest.mark.parametrize("seed", range(8))
def test_the_qp_solver_is_given_the_dense_constraints_nonzeros_in_canonical_order(
    seed: int,
) -> None:
    """Clarabel's constraint matrix, made from the equalities' nonzeros and the bounds
    (not from a dense matrix of them, tens of millions of entries on a long façade), is
    the dense ``[E; -I_lower; I_upper]``: the same entries, column by column with the rows
    in order (canonical), so Clarabel is given the same problem, value for value."""
    rng = np.random.default_rng(seed)
    e, d = random_system(seed, rows=10 + seed, variables=14)
    n = e.shape[1]
    made = bounded(e, d, np.where(rng.random(n) < 0.6, 0.0, -np.inf), np.full(n, np.inf))
    made.upper = np.where(rng.random(n) < 0.3, 5.0, np.inf)
    low, high = np.flatnonzero(np.isfinite(made.lower)), np.flatnonzero(np.isfinite(made.upper))
    matrix = sizing._constraints(made, low, high)
    expected = np.vstack([e, -np.eye(n)[low], np.eye(n)[high]])
    assert matrix.shape == expected.shape
    assert np.array_equal(_dense(matrix), expected)
    assert matrix.nnz == np.count_nonzero(expected)
    for j in range(n):  # rows in order within each column: canonical
        rows = matrix.indices[matrix.indptr[j] : matrix.indptr[j + 1]]
        assert (np.diff(rows) > 0).all()


# -- alignments sized once per axis solve -----------------------------------------------
def _solved(text: str, width: float) -> tuple[object, ...]:
    from facadecli import parse_spec, retarget, solve

    layout = solve(retarget(parse_spec(text, "generated"), width=width))
    return (
        layout.shapes,
        dict(layout.x.letters),
        dict(layout.y.letters),
        layout.x.objective,
        layout.x.proven,
        layout.warnings,
    )


@pytest.mark.parametrize(
    ("layers", "bays", "stretch"), [(6, 3, 1.07), (10, 5, 0.83), (14, 4, 1.31)]
)
def test_alignments_sized_once_give_the_layouts_sized_anew_with_fewer_programs(
    monkeypatch: pytest.MonkeyPatch, layers: int, bays: int, stretch: float
) -> None:
    """The constructions remember the alignments they sized (``sizing.sized_alignments``,
    by each group's rows and entries): generated façades at a width their words do not
    fill solve to the same layouts, byte for byte, as when every construction builds and
    solves its program anew, with fewer programs built (the work saved)."""
    from tests.benchmarks.generated import generated_spec

    text = generated_spec(layers=layers, bays=bays)
    width = round((1.0 + bays * 2.4) * stretch, 2)
    built = [0]
    build = sizing.build_program

    def counted(*args: object, **kwargs: object) -> sizing.Program:
        built[0] += 1
        return build(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(sizing, "build_program", counted)
    remembered = _solved(text, width)
    with_memory = built[0]
    sized = sizing.sized_alignments
    monkeypatch.setattr(
        sizing,
        "sized_alignments",
        lambda spec, groups, canvas, known=None: sized(spec, groups, canvas),
    )
    built[0] = 0
    anew = _solved(text, width)
    assert remembered == anew
    assert with_memory < built[0], (with_memory, built[0])
