"""``anyplan planners --settings`` lists each agent's own defaults, with ranges and units."""

from anyplan.cli.main import main


def _section(out: str, name: str) -> list[str]:
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(f"{name} "))
    rest = lines[start + 1:]
    end = next((i for i, line in enumerate(rest) if not line.startswith("    ")), len(rest))
    return [line.strip() for line in rest[:end]]


def test_st_bitstar_lists_its_own_loop_defaults_not_sequential_ones(capsys):
    main(["planners", "--settings"])
    out = capsys.readouterr().out
    st = _section(out, "st-bitstar")
    assert any(line.startswith("wait_delays_s = ()  (list of float") for line in st)
    assert any(line.startswith("max_time_s = 0.3 ") for line in st)
    seq = _section(out, "seq-bitstar")
    assert any(line.startswith("max_time_s = 0.5 ") for line in seq)
    dovs = _section(out, "dovs")
    assert "control_period_s = 0.2  (float, > 0, s): sampling period T" in dovs
