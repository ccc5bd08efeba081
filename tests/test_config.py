"""anyplan.config: one validation helper driven by field metadata, and its listing."""

from dataclasses import dataclass

import pytest

from anyplan.config import SettingError, describe, setting, validate


@dataclass(frozen=True)
class _Demo:
    dt: float = setting(0.05, lo=0.001, hi=0.05, unit="s", doc="step")
    n: int = setting(3, lo=1)
    limit: float | None = setting(None, lo=0.0, lo_open=True)
    mode: str = setting("a", choices=("a", "b"))
    flag: bool = setting(True)
    delays: tuple[float, ...] = setting((1.0,), lo=0.0, lo_open=True)
    share: float = setting(0.5, lo=0.0, hi=1.0, hi_open=True)

    def __post_init__(self) -> None:
        validate(self)


@pytest.mark.parametrize(("kw", "text"), [
    ({"dt": 0.5}, "_Demo.dt: must be in [0.001, 0.05] s, got 0.5"),
    ({"n": 0}, "_Demo.n: must be >= 1, got 0"),
    ({"n": 2.0}, "_Demo.n: must be an integer >= 1, got 2.0"),
    ({"limit": 0.0}, "_Demo.limit: must be > 0, got 0.0"),
    ({"mode": "c"}, "_Demo.mode: must be one of a, b, got 'c'"),
    ({"flag": 1}, "_Demo.flag: must be a bool, got 1"),
    ({"dt": float("nan")}, "_Demo.dt: must be a finite number, got nan"),
    ({"delays": (1.0, -1.0)}, "_Demo.delays: every item must be > 0, got -1.0"),
    ({"share": 1.0}, "_Demo.share: must be in [0, 1), got 1.0"),
])
def test_validate_names_the_class_and_the_field(kw, text):
    with pytest.raises(SettingError) as err:
        _Demo(**kw)
    assert str(err.value) == text and err.value.field == next(iter(kw))


@pytest.mark.parametrize(("kw", "text"), [
    ({"dt": 10**400}, "_Demo.dt: must be a finite number, got 1000"),
    ({"n": -(10**400)}, "_Demo.n: must be a finite number, got -1000"),
    ({"limit": 10**400}, "_Demo.limit: must be a finite number, got 1000"),
    ({"delays": (1.0, 10**400)}, "_Demo.delays: every item must be a finite number, got 1000"),
])
def test_an_integer_beyond_the_float_range_is_refused_in_a_short_line(kw, text):
    # math.isfinite raised an OverflowError here
    with pytest.raises(SettingError) as err:
        _Demo(**kw)
    assert str(err.value).startswith(text) and len(str(err.value)) < 100


def test_valid_values_pass_and_describe_lists_specs():
    _Demo(dt=0.01, n=5, limit=2, mode="b", flag=False)
    rows = {f.name: f for f in describe(_Demo)}
    assert rows["dt"].line() == "dt = 0.05  (float, in [0.001, 0.05], s): step"
    assert rows["limit"].type_name == "float or None"
    assert describe(_Demo(n=7))[1].default == 7  # an instance's values are the defaults


@pytest.mark.parametrize(("cls", "field", "bad"), [
    ("anyplan.control.kanayama:KanayamaGains", "k_y", -1.0),
    ("anyplan.agents.safety:SafetyConfig", "horizon_s", 0.0),
    ("anyplan.agents.safety:SafetyConfig", "offsets_m", (0.6, -1.0)),
    ("anyplan.prediction.tracking:TrackerConfig", "drop_after_s", 0.0),
    ("anyplan.prediction.tracking:TrackerConfig", "sigma_m", float("nan")),
])
def test_every_settings_dataclass_validates_through_the_helper(cls, field, bad):
    import importlib

    mod, name = cls.split(":")
    klass = getattr(importlib.import_module(mod), name)
    with pytest.raises(SettingError, match=rf"^{name}\.{field}: "):
        klass(**{field: bad})
    assert {f.name for f in describe(klass())} >= {field}
