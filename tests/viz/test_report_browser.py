"""The interactive report in a real headless browser (Chromium driven by Playwright).

Skipped cleanly when Playwright or a Chromium binary is missing. The page is opened from a
file:// address with the network switched off: it must work offline, from one file.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parents[1] / "experiments"))

import anyplan_bench_test_agents as agents

from anyplan.cli.main import main

agents.register_all()

sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")


def _chromium() -> str | None:
    for name in (os.environ.get("ANYPLAN_CHROMIUM"), "chromium", "chromium-browser", "google-chrome"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


CHROMIUM = _chromium()
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="no Chromium binary installed")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("report")
    scen = tmp / "tiny.yaml"
    scen.write_text(yaml.safe_dump(agents.TINY))
    db = tmp / "r.db"
    assert main(["bench", "--suite", str(scen), "--planners", "straight,half-speed", "--runs", "2",
                 "--jobs", "1", "--db", str(db), "--no-progress"]) == 0
    assert main(["report", str(db), "--out", str(tmp / "rep")]) == 0
    return tmp / "rep" / "report.html"


@pytest.fixture(scope="module")
def page(report, tmp_path_factory):
    profile = tmp_path_factory.mktemp("chromium-profile")
    with sync_api.sync_playwright() as pw:
        ctx = pw.chromium.launch_persistent_context(str(profile), executable_path=CHROMIUM, args=FLAGS,
                                                    headless=True, offline=True)
        pg = ctx.new_page()
        errors: list[str] = []
        requests: list[str] = []
        pg.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.on("request", lambda r: requests.append(r.url))
        pg.goto(report.as_uri())
        pg.wait_for_selector("#plots-box svg")
        yield pg, errors, requests
        ctx.close()


def test_page_loads_offline_without_console_errors(page):
    pg, errors, requests = page
    assert errors == []
    # One self-contained file: nothing but the page itself (and inline data: images) is fetched.
    assert all(u.startswith(("file:", "data:")) for u in requests), requests
    assert "anyplan benchmark report" in pg.title()


def test_table_of_contents_navigates(page):
    pg, errors, _ = page
    pg.click("#toc a[href='#paper']")
    assert pg.evaluate("location.hash") == "#paper"
    assert pg.evaluate("document.querySelector('#toc a.active').getAttribute('href')") == "#paper"
    top = pg.evaluate("document.getElementById('paper').getBoundingClientRect().top")
    assert abs(top) < 5  # scrolled to the section
    assert errors == []


def test_tables_sort_on_click(page):
    pg, _, _ = page
    col = "#runs-table tbody tr td:nth-child(1)"
    pg.click("#runs-table th:nth-child(1)")
    up = [int(x) for x in pg.eval_on_selector_all(col, "els => els.map(e => e.textContent)")]
    pg.click("#runs-table th:nth-child(1)")
    down = [int(x) for x in pg.eval_on_selector_all(col, "els => els.map(e => e.textContent)")]
    assert up == sorted(up) and down == sorted(up, reverse=True) and len(up) == 4


def test_table_cell_drills_down_to_its_runs(page):
    pg, errors, _ = page
    # The half-speed table's path-length cell of 1 moving obstacle: its 2 successful runs.
    cell = pg.locator("section#tables table").nth(1).locator("a.drill").nth(1)
    ids = cell.get_attribute("data-runs").split()
    assert len(ids) == 2
    cell.click()
    assert pg.evaluate("location.hash") == "#runs"
    shown = pg.eval_on_selector_all("#runs-table tbody tr:not(.hidden)",
                                    "els => els.map(e => e.getAttribute('data-id'))")
    assert sorted(shown) == sorted(ids)
    assert "2 run(s) behind" in pg.text_content("#runs-filter")
    pg.click("#runs-all")
    assert pg.locator("#runs-table tbody tr:not(.hidden)").count() == 4
    assert errors == []


def test_plot_hover_shows_values_and_click_drills_down(page):
    pg, errors, _ = page
    dot = pg.locator("#plots-box svg circle.pt").first
    dot.hover()
    tip = pg.locator(".tip")
    assert tip.is_visible() and "moving obstacles" in tip.text_content() and "n = " in tip.text_content()
    dot.click()
    assert pg.locator("#runs-table tbody tr:not(.hidden)").count() >= 1
    assert errors == []


def test_run_playback_animates_the_trajectory(page):
    pg, errors, _ = page
    pg.click("#runs-all") if pg.locator("#runs-all").count() else None
    run_id = pg.locator("#runs-table tbody tr").first.get_attribute("data-id")
    pg.click(f"button.play[data-run='{run_id}']")
    assert pg.evaluate("location.hash") == "#playback"
    assert f"Run {run_id}:" in pg.text_content("#pb-title")
    pg.wait_for_function("window.anyplanPlayback.t > 0.5")
    t1 = pg.evaluate("window.anyplanPlayback.t")
    pixels = pg.evaluate("""() => { const c = document.getElementById('pb-canvas');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n; }""")
    assert pixels > 1000  # something is drawn
    pg.wait_for_function(f"window.anyplanPlayback.t > {t1}")
    assert "t = " in pg.text_content("#pb-time")
    pg.click("#pb-play")  # pause
    t2 = pg.evaluate("window.anyplanPlayback.t")
    pg.wait_for_timeout(300)
    assert pg.evaluate("window.anyplanPlayback.t") == t2
    assert errors == []
