"""Types of the grammar search's compiled inner loop (``_adp.c``)."""

from collections.abc import Callable, Sequence

Provided = list[tuple[float, float, int, tuple[int, ...], tuple[int, ...], tuple[int, ...]]]

class Table:
    def __init__(self, provide: Callable[[int], Provided]) -> None: ...
    def add_entry(self, key: tuple[int, int, int, int, int]) -> int: ...
    def provide(self, entry: int) -> None: ...
    def greedy(self, start: int, stop_at: float) -> list[tuple[int, int]] | None: ...
    def survey(self, actions: Sequence[int]) -> tuple[float, list[list[int]]]: ...
    def adp(
        self,
        start: int,
        greedy: Sequence[int],
        iterations: int,
        state: Sequence[int],
        optimistic: float,
        stop_at: float,
    ) -> tuple[list[tuple[int, int]], int, int]: ...
