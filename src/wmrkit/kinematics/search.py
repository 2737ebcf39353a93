"""Bounded searches over sets of velocities (assignable sets 4.8, minimal actuator and sensor sets, Figs. 4.4-4.5).

The number of candidate sets grows as ``C(n, m)``: 6,545 for 16 castors, 341,376 for 64. A search here walks the
candidates in lexicographic order (depth-first, :class:`PrunedCombinations`, with a null-space prefilter), in
batches, through a cheap *necessary* test (the null-space test (4.5): the
rows ``B_a`` of a null-space basis invertible, a batch of ``m x m`` matrices), then confirms the survivors with
the exact test of the caller, and stops after ``limit`` sets found, :data:`MAX_CANDIDATES` candidates walked or
:data:`WALK_WORK` spent in the prefilter (each candidate costs an SVD of ``m x m`` per configuration: with the
self-motions of double wheels ``m`` grows with the wheel count, and 8 of them walked a million 9 x 9 candidates).
The result is a :class:`SetList`: a tuple of sets that says whether it is complete. A tqdm bar shows a long walk
(on a terminal only). Costs against the wheel count are in ``docs/limits.md``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterator, Sequence

import numpy as np

from .linalg import matrix_rank, rank_cutoff

#: Most sets a search lists; more are reported as "more than MAX_SETS".
MAX_SETS = 1000
#: Most minimal actuator / sensor sets listed (each is confirmed by an exact tree of the robot's size).
MAX_MINIMAL_SETS = 24
#: Most candidate sets walked by one search; a longer walk stops and says so.
MAX_CANDIDATES = 2_000_000
#: Work of the exact tests of one search, in units of ``rows * columns**2`` of the matrices decomposed (SVD,
#: pseudo-inverse): about 5 s on the reference machine of ``docs/limits.md``; a search stops when it is spent.
EXACT_WORK = 1e8
#: Work of the prefilter of one search, in units of ``m**3`` per candidate and configuration (the SVD of ``B_a``):
#: about 2 s on the reference machine of ``docs/limits.md``; the walk stops when it is spent.
WALK_WORK = 5e7
#: Candidates tested at once (prefilter), and exact tests at once.
BATCH, EXACT_BATCH = 8192, 64
#: Searches of more candidates than this are pruned by the prefilter.
PRUNE_FROM = 512
#: Walks longer than this show a progress bar (on a terminal).
PROGRESS_FROM = 50_000

Test = Callable[[np.ndarray], np.ndarray]


class SetList(tuple):
    """A tuple of sets found by a search; ``complete`` is False when it stopped early (``note`` says why)."""

    complete: bool
    note: str

    def __new__(cls, items: Sequence[tuple] = (), complete: bool = True, note: str = "") -> SetList:
        out = super().__new__(cls, items)
        out.complete, out.note = complete, note
        return out

    def describe_count(self) -> str:
        """``"12"``, or ``"more than 1000 (the first 1000 listed)"`` when incomplete."""
        return str(len(self)) if self.complete else f"{len(self)} listed; {self.note}"


def null_space_prefilter(a: np.ndarray, m: int, offset: int = 0, every: bool = True) -> Test:
    """The null-space test (4.5) as a prefilter: candidates (columns of A, minus `offset`) whose rows ``B_a`` of a
    null-space basis of `a` ``(..., R, k)`` are invertible at every configuration of the batch (not `every`: at
    one of them at least, as a generically assignable set is)."""
    from .nullspace import null_space_basis

    basis = null_space_basis(a, m)
    reduce = np.all if every else np.any

    def test(sets: np.ndarray) -> np.ndarray:
        b_a = np.moveaxis(basis[..., sets + offset, :], -3, 0)  # (S, ..., m, m)
        return reduce((matrix_rank(b_a) == m).reshape(len(sets), -1), axis=1)

    test.rows = lambda cols: basis[..., np.asarray(cols, dtype=int) + offset, :]  # type: ignore[attr-defined]
    test.every = every  # type: ignore[attr-defined]
    return test


class PrunedCombinations:
    """The combinations of `size` of `columns` whose rows of an orthonormal null-space basis (``rows(cols) ->
    (..., len(cols), size)``) are independent at every configuration, in lexicographic order, by a depth-first walk
    that drops a prefix whose rows are dependent or cannot reach rank `size` with the columns after it. Both are
    necessary for the prefilter (the rows of an orthonormal basis have singular values at most 1, and dropping rows
    only raises the smallest one), so it yields exactly the candidates :func:`null_space_prefilter` passes, without
    walking the ``C(n, size)`` others one by one (a geared ring of 16 double wheels: 6**8 sets among C(51, 8)).
    ``nodes`` counts the rank tests (the work; the walk ends at `budget` of them), ``covered`` the candidates
    yielded or dropped so far. Not `every`: independent at one configuration at least (both tests at the same one),
    the prefilter of the generically assignable sets."""

    def __init__(self, columns: Sequence[int], size: int, rows: Callable[[Sequence[int]], np.ndarray],
                 budget: int, every: bool = True) -> None:
        self.columns, self.size, self.rows, self.budget = list(columns), size, rows, budget
        self.reduce = np.all if every else np.any
        self.nodes = self.covered = 0

    def _full(self, cols: list[int], rank: int) -> np.ndarray:
        """Per configuration ``(...)`` bool: the rows of `cols` have rank `rank`."""
        self.nodes += 1
        s = np.linalg.svd(self.rows(cols), compute_uv=False)
        return s[..., rank - 1] > rank_cutoff(s)[..., 0] if s.shape[-1] >= rank else np.zeros(s.shape[:-1], bool)

    def _keep(self, cand: list[int], rest: list[int]) -> bool:
        ok = self._full(cand, len(cand))
        if not self.reduce(ok) or not rest:
            return bool(self.reduce(ok))
        return bool(self.reduce(ok & self._full(cand + rest, self.size)))

    def __iter__(self):
        return self._walk([], 0)

    def _walk(self, prefix: list[int], start: int):
        n, need = len(self.columns), self.size - len(prefix) - 1
        for i in range(start, n - need):
            if self.nodes >= self.budget:
                return
            cand = [*prefix, self.columns[i]]
            if not self._keep(cand, self.columns[i + 1:] if need else []):
                self.covered += math.comb(n - i - 1, need)
            elif need == 0:
                self.covered += 1
                yield tuple(cand)
            else:
                yield from self._walk(cand, i + 1)


def null_space_cost(shape: Sequence[int], m: int) -> float:
    """Work of :func:`null_space_prefilter` per candidate on matrices of `shape` ``(..., R, k)`` (units of
    :data:`WALK_WORK`): an ``m x m`` SVD per configuration."""
    return max(m, 1) ** 3 * max(math.prod(shape[:-2]), 1)


def exact_budget(shape: Sequence[int], per_test: int = 1) -> int:
    """How many exact tests of matrices of `shape` ``(..., R, k)`` fit in :data:`EXACT_WORK` (at least 4);
    `per_test`: decompositions per test."""
    *batch, rows, cols = shape
    work = max(rows, cols) * min(rows, cols) ** 2 * max(math.prod(batch), 1) * per_test
    return max(4, int(EXACT_WORK / max(work, 1)))


def search_sets(columns: Sequence[int], size: int, exact: Test, *, prefilter: Test | None = None,
                limit: int = MAX_SETS, max_exact: int | None = None, walk_cost: float = 0.0,
                what: str = "sets") -> tuple[list[tuple[int, ...]], bool, str]:
    """Sets of `size` of `columns` passing `exact`, lexicographic, at most `limit` of them.

    `exact` and `prefilter` map candidates ``(S, size)`` int to ``(S,)`` bool; `prefilter` must be a necessary
    condition of `exact` (it only prunes). At most `max_exact` candidates reach `exact` (None: no bound; see
    :func:`exact_budget`), and at most :data:`WALK_WORK` / `walk_cost` go through `prefilter` (`walk_cost`: its
    work per candidate, :func:`null_space_cost`). Returns ``(sets, complete, note)``.
    """
    total = math.comb(len(columns), size)
    candidates: Iterator[tuple[int, ...]] = itertools.combinations(columns, size)
    pruned = None
    found: list[tuple[int, ...]] = []
    walked = tested = 0
    from tqdm import tqdm

    if total <= PRUNE_FROM:  # small searches: the exact test alone, as it always was
        prefilter = None
    max_walk = MAX_CANDIDATES
    if prefilter is not None and walk_cost > 0:
        max_walk = min(MAX_CANDIDATES, max(1, int(WALK_WORK / walk_cost)))
    if prefilter is not None and hasattr(prefilter, "rows") and size > 0:
        pruned = PrunedCombinations(columns, size, prefilter.rows, max_walk, getattr(prefilter, "every", True))
        candidates, prefilter = iter(pruned), None  # it yields exactly what the prefilter passes
    with tqdm(total=total, disable=None if total > PROGRESS_FROM else True, leave=False, unit="set",
              desc=f"searching {what}") as bar:
        while True:
            chunk = list(itertools.islice(candidates, min(BATCH, max_walk)))
            if pruned is not None:  # its work is its rank tests; its progress, the candidates yielded or dropped
                bar.update(pruned.covered - walked)
                walked = pruned.covered
            if not chunk and (pruned is None or walked >= total):
                return found, True, ""
            batch = np.array(chunk, dtype=int).reshape(len(chunk), size)
            if pruned is None:
                walked += len(batch)
                bar.update(len(batch))
            if prefilter is not None:
                batch = batch[np.asarray(prefilter(batch), dtype=bool)]
            start = 0
            while start < len(batch):
                if max_exact is not None and tested >= max_exact:
                    return found, False, f"search stopped after {tested} exact tests (docs/limits.md)"
                size_ = min(EXACT_BATCH, max(limit + 1 - len(found), 8))
                part = batch[start:start + (size_ if max_exact is None else min(size_, max_exact - tested))]
                tested += len(part)
                found += [tuple(int(c) for c in s) for s in part[np.asarray(exact(part), dtype=bool)]]
                start += len(part)
                if len(found) > limit:
                    return found[:limit], False, f"more than {limit} {what} (the first {limit} listed)"
            if (pruned.nodes if pruned is not None else walked) >= max_walk and walked < total:
                return found, False, (f"search stopped after {walked} of {total} candidate {what} "
                                      "(docs/limits.md)")
