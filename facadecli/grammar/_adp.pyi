"""Types of the compiled grammar search (``_adp.c``)."""

from collections.abc import Sequence
from typing import Literal

class Table:
    def __init__(
        self,
        labels: bytes,
        rows: int,
        cols: int,
        xs: bytes,
        ys: bytes,
        qx: float,
        qy: float,
        background: int,
    ) -> None: ...
    def prepare(self, repeats: bytes, extensions: int, split: float, repeat: float) -> None: ...
    def content(self, r0: int, r1: int, c0: int, c1: int) -> tuple[int, int]: ...
    def entry(self, r0: int, r1: int, c0: int, c1: int) -> int: ...
    def action_id(self, entry: int, index: int) -> int: ...
    def action(
        self, id: int
    ) -> tuple[
        tuple[int, int, int, int], Literal["x", "y"], tuple[int, ...], tuple[int, ...], float
    ]: ...
    def explored(self) -> int: ...
    def describe(
        self, entry: int
    ) -> list[tuple[str, str, tuple[int, ...], tuple[int, ...], int, int, float, float]]: ...
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
