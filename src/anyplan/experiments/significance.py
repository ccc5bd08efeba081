"""How sure a benchmark's outcome counts are: confidence intervals and paired comparisons.

A success rate over n runs is an estimate. Two planners run on the same scenarios and seeds give
*paired* outcomes, and their fair comparison rests on the runs where they disagree.

* :func:`wilson_interval`: the Wilson score interval of a proportion (E. B. Wilson, JASA 22,
  1927), near its nominal coverage for small n and for rates near 0 or 1, where the normal
  ("Wald") interval is not (Brown, Cai & DasGupta, Statistical Science 16, 2001).
* :func:`mcnemar_p`: McNemar's exact test of paired outcomes (Q. McNemar, Psychometrika 12,
  1947): without a difference each discordant pair falls either way with probability 1/2.
* :func:`paired_difference`: the difference of two paired rates and Newcombe's interval for it
  (method 10 of R. G. Newcombe, Statistics in Medicine 17, 1998, pp. 2635-2650).
* :func:`compare_outcomes`: both, over the runs (keys) that two result sets share.

``docs/experiments.md``, "How sure a difference is", says how the benchmarks use them.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from statistics import NormalDist

__all__ = ["PairedComparison", "compare_outcomes", "mcnemar_p", "paired_difference",
           "wilson_interval"]


def _z(level: float) -> float:
    """The two-sided standard normal quantile of confidence ``level`` (1.96 at 0.95)."""
    if not (isinstance(level, int | float) and 0.0 < level < 1.0):
        raise ValueError(f"level: must be in (0, 1), got {level!r}")
    return NormalDist().inv_cdf(0.5 + 0.5 * float(level))


def _count(name: str, value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{name}: must be a count (an int >= 0), got {value!r}")
    return value


def wilson_interval(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """The Wilson score interval ``(low, high)`` of a proportion with ``k`` of ``n`` successes.

    With no runs (n = 0) the interval is the whole of [0, 1]: nothing is known.

    Examples:
        >>> lo, hi = wilson_interval(59, 120)
        >>> round(lo, 4), round(hi, 4)
        (0.4039, 0.58)
        >>> wilson_interval(0, 10)[0]
        0.0
    """
    k, n = _count("k", k), _count("n", n)
    if k > n:
        raise ValueError(f"k: {k} successes of n = {n} runs")
    z = _z(level)
    if n == 0:
        return 0.0, 1.0
    p = k / n
    z2n = z * z / n
    centre = (p + 0.5 * z2n) / (1.0 + z2n)
    half = z * math.sqrt(p * (1.0 - p) / n + 0.25 * z2n / n) / (1.0 + z2n)
    lo = 0.0 if k == 0 else max(0.0, centre - half)
    hi = 1.0 if k == n else min(1.0, centre + half)
    return lo, hi


def mcnemar_p(only_a: int, only_b: int) -> float:
    """Two-sided exact p-value of McNemar's test: ``only_a`` runs where A alone succeeded,
    ``only_b`` where B alone did (the pairs where both, or neither, succeeded carry no
    information about a difference). 1.0 when there is no discordant pair.

    Examples:
        >>> round(mcnemar_p(25, 10), 4)
        0.0167
        >>> mcnemar_p(1, 0)
        1.0
    """
    only_a, only_b = _count("only_a", only_a), _count("only_b", only_b)
    m = only_a + only_b
    if m == 0:
        return 1.0
    tail = sum(math.comb(m, i) for i in range(min(only_a, only_b) + 1))
    return min(1.0, 2 * tail / 2**m)


@dataclass(frozen=True)
class PairedComparison:
    """Paired outcomes of A and B over ``n`` runs, and what they say about A's rate - B's.

    Attributes:
        both, only_a, only_b, neither: Runs where both, A alone, B alone, neither had the
            outcome (e.g. reached the goal).
        level: Confidence level of ``interval``.
        interval: Newcombe's interval ``(low, high)`` of ``difference``.
        p_value: McNemar's exact two-sided p-value.
    """

    both: int
    only_a: int
    only_b: int
    neither: int
    level: float
    interval: tuple[float, float]
    p_value: float

    @property
    def n(self) -> int:
        """Paired runs."""
        return self.both + self.only_a + self.only_b + self.neither

    @property
    def rate_a(self) -> float:
        """A's rate."""
        return (self.both + self.only_a) / self.n

    @property
    def rate_b(self) -> float:
        """B's rate."""
        return (self.both + self.only_b) / self.n

    @property
    def difference(self) -> float:
        """A's rate - B's rate."""
        return (self.only_a - self.only_b) / self.n

    def fmt(self, percent: bool = True) -> str:
        """``+7.5 % [+1.2, +13.6] (p = 0.021)``: the difference, its interval and McNemar's p."""
        s = 100.0 if percent else 1.0
        u = " %" if percent else ""
        lo, hi = self.interval
        return (f"{s * self.difference:+.1f}{u} [{s * lo:+.1f}, {s * hi:+.1f}] "
                f"(p = {self.p_value:.2g})")


def paired_difference(both: int, only_a: int, only_b: int, neither: int,
                      level: float = 0.95) -> PairedComparison:
    """The paired comparison of the 2 x 2 table ``both, only_a, only_b, neither``.

    Newcombe's method 10: the Wilson intervals of the two rates, combined with the correlation
    phi of the paired outcomes (its continuity-corrected form: ``AD - BC`` is reduced by n / 2
    when above it and counts as 0 between 0 and n / 2).

    Examples:
        Of 41 runs, 14 reached by both, 5 by A alone, none by B alone:

        >>> c = paired_difference(14, 5, 0, 22)
        >>> round(c.difference, 3), c.interval[0] > 0.0, round(c.p_value, 4)
        (0.122, True, 0.0625)
    """
    a, b = _count("both", both), _count("only_a", only_a)
    c, d = _count("only_b", only_b), _count("neither", neither)
    n = a + b + c + d
    if n == 0:
        raise ValueError("paired_difference: no paired runs")
    p1, p2 = (a + b) / n, (a + c) / n
    l1, u1 = wilson_interval(a + b, n, level)
    l2, u2 = wilson_interval(a + c, n, level)
    margins = (a + b) * (c + d) * (a + c) * (b + d)
    ad_bc = a * d - b * c
    corrected = ad_bc - 0.5 * n if ad_bc > 0.5 * n else (ad_bc if ad_bc < 0 else 0.0)
    phi = corrected / math.sqrt(margins) if margins > 0 else 0.0
    delta = p1 - p2
    dl = (p1 - l1) ** 2 - 2.0 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2) ** 2
    du = (u1 - p1) ** 2 - 2.0 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2) ** 2
    lo = max(-1.0, delta - math.sqrt(max(dl, 0.0)))
    hi = min(1.0, delta + math.sqrt(max(du, 0.0)))
    return PairedComparison(a, b, c, d, float(level), (lo, hi), mcnemar_p(b, c))


def compare_outcomes(a: Mapping[Hashable, bool], b: Mapping[Hashable, bool],
                     level: float = 0.95) -> PairedComparison:
    """:func:`paired_difference` over the keys (runs, e.g. ``(scenario, seed)``) that ``a`` and
    ``b`` share; each maps a run to whether it had the outcome. Keys in only one are left out.

    Examples:
        >>> a = {("w1", 0): True, ("w2", 0): True, ("w3", 0): False}
        >>> b = {("w1", 0): True, ("w2", 0): False, ("w3", 0): False, ("w4", 0): True}
        >>> c = compare_outcomes(a, b)
        >>> (c.n, c.both, c.only_a, c.only_b, c.neither)
        (3, 1, 1, 0, 1)
    """
    keys = [k for k in a if k in b]
    if not keys:
        raise ValueError("compare_outcomes: the two result sets share no run")
    both = sum(bool(a[k]) and bool(b[k]) for k in keys)
    only_a = sum(bool(a[k]) and not b[k] for k in keys)
    only_b = sum(bool(b[k]) and not a[k] for k in keys)
    return paired_difference(both, only_a, only_b, len(keys) - both - only_a - only_b, level)
