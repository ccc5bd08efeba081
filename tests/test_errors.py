"""The shared number check (:func:`anyplan.errors.finite_float`): what it refuses and why."""

from __future__ import annotations

import math

import numpy as np
import pytest

from anyplan.errors import NumberRefused, finite_float


@pytest.mark.parametrize(("value", "kind"), [
    (True, "type"), (False, "type"), (None, "type"), ("1.5", "type"), ([1.0], "type"),
    (np.int64(3), "type"),  # not an int: as every caller refused it before
    (10**400, "overflow"), (-(10**400), "overflow"),
    (math.nan, "nonfinite"), (math.inf, "nonfinite"), (-math.inf, "nonfinite"),
])
def test_anything_but_a_finite_int_or_float_is_refused(value, kind):
    with pytest.raises(NumberRefused) as info:
        finite_float(value)
    assert info.value.kind == kind
    assert isinstance(info.value, ValueError) and "\n" not in str(info.value)


def test_a_huge_int_is_refused_in_one_short_line_not_an_overflow_error():
    with pytest.raises(NumberRefused) as info:
        finite_float(10**400, hi=10.0)
    assert str(info.value) == "number too large (beyond the floating-point range)"
    assert len(info.value.shown) <= 40 and info.value.shown.startswith("100")


def test_ints_and_floats_come_back_as_floats():
    assert finite_float(3) == 3.0 and type(finite_float(3)) is float
    assert finite_float(-2.5) == -2.5
    assert finite_float(np.float64(0.5)) == 0.5 and type(finite_float(np.float64(0.5))) is float
    assert finite_float(10**300) == 1e300  # a large int within the float range is accepted


@pytest.mark.parametrize(("value", "lo_open", "hi", "outcome"), [
    (0.0, False, 1.0, 0.0),      # closed lower bound: the bound itself is in
    (0.0, True, 1.0, "low"),     # open lower bound: the bound itself is out
    (1e-300, True, 1.0, 1e-300),  # ... anything above it is in
    (-1e-300, False, 1.0, "low"),
    (1.0, False, 1.0, 1.0),      # the upper bound is closed
    (1.0 + 1e-15, False, 1.0, "high"),
])
def test_bounds_are_open_or_closed_below_and_closed_above(value, lo_open, hi, outcome):
    if isinstance(outcome, str):
        with pytest.raises(NumberRefused) as info:
            finite_float(value, 0.0, hi, lo_open=lo_open)
        assert info.value.kind == outcome
    else:
        assert finite_float(value, 0.0, hi, lo_open=lo_open) == outcome


def test_the_upper_bound_is_open_when_asked():
    assert finite_float(1.0 - 1e-15, hi=1.0, hi_open=True) == 1.0 - 1e-15
    with pytest.raises(NumberRefused, match=r"^must be < 1, got 1$") as info:
        finite_float(1.0, hi=1.0, hi_open=True)
    assert info.value.kind == "high"


def test_the_reason_names_the_bound_and_shows_the_value():
    for kwargs, reason in (({"lo": 0.0, "lo_open": True}, "must be > 0, got -1"),
                           ({"lo": 0.5}, "must be >= 0.5, got -1"),
                           ({"hi": -2.0}, "must be <= -2, got -1")):
        with pytest.raises(NumberRefused, match=f"^{reason}$") as info:
            finite_float(-1, **kwargs)
        assert info.value.shown == "-1"
