"""Confidence intervals and paired tests of benchmark outcomes (anyplan.experiments.significance)."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.stats import binomtest

from anyplan.experiments.significance import (
    compare_outcomes,
    mcnemar_p,
    paired_difference,
    wilson_interval,
)

# Reference values from statsmodels 0.15 (proportion_confint(k, n, method="wilson") and
# contingency_tables.mcnemar(exact=True)), computed once outside the project.
WILSON = [((0, 10), (0.0, 0.27753279986288926)), ((59, 120), (0.4038757172769723, 0.5799746021633395)),
          ((169, 200), (0.7883930940765792, 0.8886036307231068)), ((10, 10), (0.7224672001371106, 1.0)),
          ((1, 3), (0.06149194472039626, 0.7923403991979523))]
MCNEMAR = [((0, 0), 1.0), ((3, 9), 0.14599609375), ((25, 10), 0.016673847800120715), ((1, 0), 1.0),
           ((17, 46), 0.00033670934946623826)]


@pytest.mark.parametrize(("kn", "expected"), WILSON)
def test_wilson_interval_matches_the_reference(kn, expected):
    assert wilson_interval(*kn) == pytest.approx(expected, abs=1e-12)


@given(n=st.integers(1, 500), data=st.data(), level=st.floats(0.5, 0.999))
def test_wilson_interval_holds_the_estimate_and_widens_with_the_level(n, data, level):
    k = data.draw(st.integers(0, n))
    lo, hi = wilson_interval(k, n, level)
    assert 0.0 <= lo <= k / n <= hi <= 1.0
    lo2, hi2 = wilson_interval(k, n, min(0.9999, level + 0.0005))
    assert lo2 <= lo and hi2 >= hi


@pytest.mark.parametrize(("bc", "expected"), MCNEMAR)
def test_mcnemar_matches_the_reference(bc, expected):
    assert mcnemar_p(*bc) == pytest.approx(expected, rel=1e-12)


@given(b=st.integers(0, 300), c=st.integers(0, 300))
def test_mcnemar_is_the_exact_binomial_test_of_the_discordant_pairs(b, c):
    expected = 1.0 if b + c == 0 else binomtest(b, b + c, 0.5).pvalue
    assert mcnemar_p(b, c) == pytest.approx(expected, rel=1e-9, abs=1e-300)
    assert mcnemar_p(b, c) == mcnemar_p(c, b)


def test_mcnemar_keeps_its_level_without_a_difference():
    # A and B differ on a run with probability 0.2, either way alike: an exact test rejects at
    # 5 % in at most 5 % of the experiments (it is conservative).
    rng = np.random.default_rng(7)
    draws = rng.multinomial(120, (0.5, 0.1, 0.1, 0.3), size=4000)
    rejected = np.mean([mcnemar_p(int(d[1]), int(d[2])) < 0.05 for d in draws])
    assert rejected <= 0.05


def test_newcombe_interval_on_a_table_with_one_sided_discordance():
    # Altman, Machin, Bryant & Gardner, "Statistics with Confidence" (2000), Table 6.2: 14
    # concordant successes, 5 and 0 discordant pairs, 22 concordant failures.
    c = paired_difference(14, 5, 0, 22)
    assert c.difference == pytest.approx(5 / 41)
    assert c.p_value == pytest.approx(2 / 2**5)  # five discordant pairs, all one way
    lo, hi = c.interval
    # narrower than the two Wilson intervals' square-and-add without correlation (phi = 0):
    # the outcomes are positively correlated, which pairing exploits
    p1, p2 = 19 / 41, 14 / 41
    l1, u1 = wilson_interval(19, 41)
    l2, u2 = wilson_interval(14, 41)
    d = p1 - p2
    assert d - ((p1 - l1) ** 2 + (u2 - p2) ** 2) ** 0.5 < lo < d
    assert d < hi < d + ((u1 - p1) ** 2 + (p2 - l2) ** 2) ** 0.5


@given(t=st.tuples(*[st.integers(0, 60)] * 4).filter(lambda t: sum(t) > 0),
       level=st.floats(0.5, 0.999))
def test_newcombe_interval_is_antisymmetric_and_holds_the_estimate(t, level):
    a, b, c, d = t
    ab, ba = paired_difference(a, b, c, d, level), paired_difference(a, c, b, d, level)
    assert ab.interval == pytest.approx((-ba.interval[1], -ba.interval[0]), abs=1e-12)
    lo, hi = ab.interval
    assert -1.0 <= lo <= ab.difference + 1e-12 and ab.difference - 1e-12 <= hi <= 1.0
    assert ab.p_value == ba.p_value


@pytest.mark.parametrize("probs", [(0.5, 0.1, 0.05, 0.35), (0.3, 0.2, 0.1, 0.4), (0.45, 0.02, 0.08, 0.45),
                                   (0.8, 0.05, 0.05, 0.1)])
@pytest.mark.parametrize("n", [40, 120])
def test_newcombe_interval_covers_the_true_difference_at_about_its_level(probs, n):
    # The claim of Newcombe (1998): close to nominal coverage at these sizes (seeded simulation).
    rng = np.random.default_rng(11)
    true = probs[1] - probs[2]
    draws = rng.multinomial(n, probs, size=2000)
    hits = [paired_difference(*map(int, d)).interval for d in draws]
    coverage = np.mean([lo <= true <= hi for lo, hi in hits])
    assert coverage >= 0.93


def test_compare_outcomes_pairs_the_shared_runs_only():
    a = {("w1", 0): True, ("w2", 0): True, ("w3", 0): False, ("w3", 1): True}
    b = {("w1", 0): True, ("w2", 0): False, ("w3", 0): True, ("w9", 0): True}
    c = compare_outcomes(a, b)
    assert (c.n, c.both, c.only_a, c.only_b, c.neither) == (3, 1, 1, 1, 0)
    assert c.difference == 0.0 and c.p_value == 1.0
    with pytest.raises(ValueError, match="share no run"):
        compare_outcomes({"x": True}, {"y": True})


@pytest.mark.parametrize(("call", "field"), [
    (lambda: wilson_interval(-1, 3), "k"), (lambda: wilson_interval(4, 3), "k"),
    (lambda: wilson_interval(1, 3, level=1.0), "level"), (lambda: mcnemar_p(1.5, 2), "only_a"),
    (lambda: paired_difference(0, 0, 0, 0), "no paired runs"),
    (lambda: paired_difference(1, True, 0, 0), "only_a")])
def test_bad_counts_are_refused_naming_the_field(call, field):
    with pytest.raises(ValueError, match=field):
        call()
