"""Types of the compiled exact alignment search (``_exact.c``)."""

from collections.abc import Callable, Mapping, Sequence

Letter = tuple[str, float | None, bool, bool, bool, bool, int]
RowSpec = tuple[Sequence[Letter], Sequence[int], Sequence[int]]
Cuts = list[list[tuple[tuple[int, int] | None, ...]]]

class Search:
    used: int
    timed_out: bool
    incumbent: float
    def __init__(
        self,
        groups: Sequence[Sequence[RowSpec]],
        variables: dict[str, int],
        target: Sequence[float],
        canvas: float,
        incumbent: float,
        limit: int,
        used: int,
        deadline: float,
        first_only: bool,
        leaf: Callable[[Cuts], tuple[float, bool]],
    ) -> None: ...
    def run(self, gaps: bool) -> int: ...
    def rejections(self) -> list[tuple[int, int, int, int, int, int, int, int]]: ...

def eliminate(
    rows: Sequence[tuple[Mapping[int, float], float]], n: int, zero: float, tolerance: float
) -> tuple[list[float], list[int], list[tuple[int, int, float]]] | None: ...
