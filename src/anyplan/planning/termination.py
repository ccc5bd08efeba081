"""Composable planner termination conditions, after OMPL's ``PlannerTerminationCondition``.

A condition is a cheap callable returning True once the planner should return. Conditions that
depend on the planner's progress (batches, cost) read it from the planner passed to
:meth:`TerminationCondition.bind`, which :meth:`solve` calls before it starts; a condition can
therefore be built before the planner exists and combined freely with :func:`any_of` and
:func:`all_of`.

Examples:
    >>> ptc = any_of(timed(0.5), target_cost(25.0))
    >>> ptc.terminate()
    >>> ptc()
    True
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

__all__ = [
    "TerminationCondition", "timed", "batches", "target_cost", "first_solution", "any_of",
    "all_of", "as_condition",
]


class TerminationCondition:
    """A callable telling a planner to return.

    Args:
        predicate: Called with the bound planner (or None); True means "stop".
        on_bind: Called once with the planner when :meth:`bind` is called (to record a
            reference point such as the start time or the current batch count).
    """

    def __init__(self, predicate: Callable[[Any], bool],
                 on_bind: Callable[[Any], None] | None = None) -> None:
        self._predicate = predicate
        self._on_bind = on_bind
        self._planner: Any = None
        self._stopped = False

    def bind(self, planner: Any) -> TerminationCondition:
        """Attach the planner whose progress the condition reads; returns ``self``."""
        self._planner = planner
        if self._on_bind is not None:
            self._on_bind(planner)
        return self

    def __call__(self) -> bool:
        """True once the predicate holds or :meth:`terminate` was called."""
        if self._stopped:
            return True
        if self._predicate(self._planner):
            self._stopped = True
        return self._stopped

    def terminate(self) -> None:
        """Make every later call return True."""
        self._stopped = True

    def __or__(self, other: TerminationCondition) -> TerminationCondition:
        return any_of(self, other)

    def __and__(self, other: TerminationCondition) -> TerminationCondition:
        return all_of(self, other)


def timed(seconds: float, clock: Callable[[], float] = time.perf_counter) -> TerminationCondition:
    """Stop ``seconds`` [s] after the condition is bound (i.e. after ``solve`` starts).

    If the condition is never bound, the clock starts when it is created.
    """
    if not seconds >= 0.0:
        raise ValueError(f"seconds must be >= 0, got {seconds}")
    start = [clock()]

    def on_bind(_planner: Any) -> None:
        start[0] = clock()

    return TerminationCondition(lambda _p: clock() - start[0] >= seconds, on_bind)


def batches(n: int) -> TerminationCondition:
    """Stop once ``n`` more batches have been started since ``solve`` was called.

    The bound planner must expose ``n_batches`` (BIT* does).
    """
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    base = [0]

    def on_bind(planner: Any) -> None:
        base[0] = int(getattr(planner, "n_batches", 0))

    return TerminationCondition(
        lambda p: p is not None and int(p.n_batches) - base[0] > n, on_bind)


def target_cost(cost: float) -> TerminationCondition:
    """Stop once the planner's ``best_cost`` [m] is at most ``cost``."""
    return TerminationCondition(lambda p: p is not None and float(p.best_cost) <= cost)


def first_solution() -> TerminationCondition:
    """Stop as soon as any solution exists."""
    return TerminationCondition(lambda p: p is not None and float(p.best_cost) < float("inf"))


def any_of(*conditions: TerminationCondition) -> TerminationCondition:
    """Stop when any of ``conditions`` says so."""
    conds = tuple(conditions)

    def on_bind(planner: Any) -> None:
        for c in conds:
            c.bind(planner)

    def pred(_p: Any) -> bool:
        fired = False
        for c in conds:  # evaluate all of them, so that each latches when it fires
            fired = c() or fired
        return fired

    return TerminationCondition(pred, on_bind)


def all_of(*conditions: TerminationCondition) -> TerminationCondition:
    """Stop when all of ``conditions`` say so."""
    conds = tuple(conditions)

    def on_bind(planner: Any) -> None:
        for c in conds:
            c.bind(planner)

    def pred(_p: Any) -> bool:
        fired = True
        for c in conds:
            fired = c() and fired
        return fired

    return TerminationCondition(pred, on_bind)


def as_condition(ptc: TerminationCondition | float | int) -> TerminationCondition:
    """A condition from a condition or a time budget [s]."""
    if isinstance(ptc, TerminationCondition):
        return ptc
    if isinstance(ptc, bool) or not isinstance(ptc, int | float):
        raise TypeError(f"expected a TerminationCondition or seconds, got {type(ptc).__name__}")
    return timed(float(ptc))
