"""The control center's pages (replay, live, plan view) in a real browser: headless Chromium (Debian's ``chromium``) driven by Playwright.

Skipped, with the reason printed, where Playwright or the browser is not installed
(``make setup`` installs both where it can). Screenshots go to ``build/center/``.
"""

from __future__ import annotations

import contextlib
import json
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from alica.io import plans_dir
from tests.center.live_run import BLOCKS, live_run, serving

if TYPE_CHECKING:
    from playwright.sync_api import Page

CHROMIUM = "/usr/bin/chromium"
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]
SHOTS = Path(__file__).resolve().parents[2] / "build" / "center"

pytestmark = pytest.mark.optional


def _browser_or_skip() -> None:
    pytest.importorskip("playwright.sync_api", reason="the playwright package is not installed")
    if shutil.which(CHROMIUM) is None:
        pytest.skip(f"no browser at {CHROMIUM}: install Debian's chromium package (apt-get install chromium)")


@contextlib.contextmanager
def _page(url: str, width: int, height: int) -> Iterator[Page]:
    """A page of headless Chromium at ``url``, once it has drawn its first state (screenshots go to SHOTS)."""
    from playwright.sync_api import sync_playwright

    SHOTS.mkdir(parents=True, exist_ok=True)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            page = browser.new_page(viewport={"width": width, "height": height})
            page.goto(url, timeout=20_000)
            page.wait_for_selector("body[data-ready=yes]", timeout=20_000)
            yield page
        finally:
            browser.close()


def _serve(*args: str) -> Iterator[str]:
    with serving(["center", *args, "--port", "0"]) as (line, _):
        yield line


@pytest.fixture()
def replay_url(recorded_trace: Path) -> Iterator[str]:
    _browser_or_skip()
    yield from _serve("--trace", str(recorded_trace))


@pytest.fixture()
def poses_url(written_trace: Path) -> Iterator[str]:
    _browser_or_skip()
    yield from _serve("--trace", str(written_trace))


@pytest.fixture()
def blocks_url(blocks_trace: Path) -> Iterator[str]:
    _browser_or_skip()
    yield from _serve("--trace", str(blocks_trace))


@pytest.fixture()
def lunar_url(lunar_trace: Path) -> Iterator[str]:
    _browser_or_skip()
    yield from _serve("--trace", str(lunar_trace))


@pytest.fixture()
def plan_url() -> Iterator[str]:
    _browser_or_skip()
    yield from _serve("--plan", str(plans_dir() / "blocksworld" / "mission.yaml"))


def test_the_replay_page_shows_the_agents_and_follows_the_slider(replay_url: str) -> None:
    with _page(replay_url, 1280, 800) as page:
        rows = page.locator("#agents-body tr")
        assert rows.count() == 3
        assert page.locator('#agents-body tr[data-agent="r1"] td').nth(4).inner_text() == "Formation"
        assert page.locator("#map-body").inner_text().strip() == "no poses in this trace"
        end = float(page.locator("#slider").get_attribute("max") or "0")
        assert end > 0
        page.click("#next-fault")
        page.wait_for_function("parseFloat(document.getElementById('slider').value) > 0", timeout=10_000)
        fault_at = float(page.locator("#slider").input_value())
        assert fault_at == pytest.approx(1.0, abs=0.2)
        page.wait_for_selector('#agents-body tr.dead[data-agent="r2"]', timeout=10_000)
        page.fill("#filter", "fault")
        page.wait_for_function("document.getElementById('log-body').rows.length >= 1", timeout=10_000)
        assert all("fault" in t for t in page.locator("#log-body tr").all_inner_texts())
        page.screenshot(path=str(SHOTS / "replay.png"), full_page=True)
        page.select_option("#speed", "10")
        page.click("#play")  # 1 s of the trace left: 0.1 s at 10x
        page.wait_for_function(
            "document.getElementById('slider').value === document.getElementById('slider').max"
            " && document.getElementById('play').textContent === 'play'",
            timeout=10_000,
        )
        assert page.locator("#time").inner_text() == f"t = {end:.3f} s"


def test_the_plan_view_draws_the_tree(plan_url: str) -> None:
    with _page(plan_url, 1400, 900) as page:
        assert page.locator("#tree svg g.plan").count() >= 1
        assert page.locator("#tree svg g.state").count() >= 2
        page.screenshot(path=str(SHOTS / "plan.png"), full_page=True)


def test_the_map_draws_robots_from_pose_events(poses_url: str) -> None:
    with _page(poses_url, 1280, 800) as page:
        assert page.locator("#map-body svg circle.robot").count() == 0  # no pose before t = 0.5
        page.click("#next-replan")
        page.wait_for_function("document.getElementById('slider').value === '2'", timeout=10_000)
        page.wait_for_selector('#map-body svg circle.robot[data-agent="a"]', timeout=10_000)
        assert page.locator('#agents-body tr[data-agent="a"] td').nth(5).inner_text() == "S2"
        page.screenshot(path=str(SHOTS / "replay-poses.png"), full_page=True)


def _slide_to(page: Page, t: str) -> None:
    """Move the slider to ``t`` (a number, or ``max``) as a person dragging it would."""
    page.eval_on_selector(
        "#slider", "(s, t) => { s.value = t === 'max' ? s.max : t; s.dispatchEvent(new Event('input')); }", t
    )


def test_a_blocks_world_replay_shows_the_blocks_table_and_the_generated_plan(blocks_url: str) -> None:
    with _page(blocks_url, 1280, 1000) as page:
        header = page.locator("#file")
        assert header.inner_text().startswith("trace.jsonl \u2014 ")  # the file's name, not where it lies
        assert Path(header.get_attribute("title") or "").is_absolute()
        assert page.locator("#blocks").is_visible()
        page.wait_for_selector("#blocks-body svg g.block", timeout=10_000)
        names = sorted(page.locator("#blocks-body svg g.block text").all_text_contents())
        assert names == ["a", "b", "c", "d"]
        page.screenshot(path=str(SHOTS / "replay-blocks.png"), full_page=True)
        _slide_to(page, "5")  # r1 unstacks a block in the leader's generated plan
        tree = page.locator('#trees-body .agent-tree[data-agent="r1"]')
        tree.locator("li.plan.generated.active").wait_for(timeout=10_000)
        generated = tree.locator("li.plan.generated.active > .name").inner_text()
        assert generated.startswith("StackBlocks_")
        current = tree.locator("li.plan.generated.active > ul > li.state.current")
        assert current.locator("> .name").inner_text() == "T0_S0_Unstack"
        inside = current.locator('> ul > li.plan.active[data-name="Unstack"]')  # drawn from the plan file
        assert inside.locator("> ul > li.state.current > .name").inner_text() == "TakeOffStack"  # its entry state
        top = tree.locator('li.plan.active[data-name="BlocksWorldMission"] > ul > li.state.current > .name')
        assert top.inner_text() == "Stacking"
        page.locator("#trees").screenshot(path=str(SHOTS / "plan-tree.png"))
        _slide_to(page, "max")
        page.wait_for_function("document.getElementById('time').textContent !== 't = 5.000 s'", timeout=10_000)
        page.wait_for_selector(
            '#trees-body .agent-tree[data-agent="r1"] li.plan.active[data-name="BlocksWorldMission"]'
            ' > ul > li.state.current[data-state="Done"]',
            timeout=10_000,
        )
        assert tree.locator("li.plan.generated").count() == 0  # left when the mission's state changed


def test_a_lunar_replay_shows_the_team_map_objects_and_found_samples(lunar_url: str) -> None:
    with _page(lunar_url, 1280, 1000) as page:
        assert not page.locator("#blocks").is_visible()
        assert page.locator("#map-body svg .grid").count() == 0  # no map before the first map event
        assert page.locator("#map-body svg g.object.rock").count() >= 1
        _slide_to(page, "max")
        page.wait_for_selector("#map-body svg .grid rect.occupied", timeout=10_000)
        assert page.locator("#map-body svg .grid rect.free").count() >= 1
        found = page.locator("#map-body svg g.object.sample.found text").all_text_contents()
        assert found and all(re.fullmatch(r"\w+: [a-z]+(-[a-z]+)+", f) for f in found), found
        assert page.locator("#map-body svg circle.robot").count() >= 2
        assert page.locator("#map-body svg polyline.track").count() >= 1
        scout = page.locator('#trees-body .agent-tree[data-agent="scout"]')
        assert scout.locator('li.plan.active[data-name="ImperaMission"] > ul > li.state.current').count() == 1
        page.screenshot(path=str(SHOTS / "replay-lunar.png"), full_page=True)


@pytest.fixture()
def live_blocks() -> Iterator[Any]:
    """A blocks-world team planning under --review, served live."""
    _browser_or_skip()
    with live_run(*BLOCKS, "--review", "--speed", "2", "--time-limit", "600") as live:
        yield live


def test_the_live_page_shows_the_team_updates_within_a_second_and_the_operator_reviews_its_plans(
    live_blocks: Any,
) -> None:
    with _page(live_blocks.url, 1400, 1000) as page:
        assert page.locator("#file").inner_text() == "mission.yaml"
        assert page.locator("#agents-body tr").count() == 2
        assert page.locator('#agents-body tr[data-agent="r2"] td').nth(1).inner_text() == "Manipulator"
        # the team runs: the page's time moves on within a second
        shown = page.locator("#status").inner_text()
        page.wait_for_function(f"document.getElementById('status').textContent !== {shown!r}", timeout=1_000)

        # the leader's first plan waits for the operator; the goal field is checked as typed
        page.wait_for_selector('.proposal[data-generation="1"]', timeout=30_000)
        page.fill("#goal", "on(c, a) and")
        page.wait_for_selector("#goal-check.bad", timeout=5_000)
        assert "column 13" in page.locator("#goal-check").inner_text()
        assert page.locator("#set-goal").is_disabled()
        page.fill("#goal", "on(c, a) and ontable(a)")
        page.wait_for_selector("#goal-check.ok", timeout=5_000)
        page.click("#set-goal")
        # the leader plans for the typed goal and shows the plan as tasks and steps
        page.wait_for_selector('.proposal[data-generation="2"]', timeout=30_000)
        proposal = page.locator('.proposal[data-generation="2"]')
        assert proposal.locator("ol.steps li").count() >= 1
        assert proposal.locator("table.tasks tr[data-task]").count() >= 1
        page.screenshot(path=str(SHOTS / "live-operator.png"), full_page=True)

        # decline: the leader plans again
        proposal.locator("button.decline").click()
        page.wait_for_selector('.proposal[data-generation="3"]', timeout=30_000)
        third = page.locator('.proposal[data-generation="3"]')
        steps = third.locator("ol.steps li").count()
        if steps > 1:  # dropping the first step breaks the plan: refused with the validator's reason
            third.locator("ol.steps li").first.locator("input[type=checkbox]").click()
            assert third.locator("ol.steps li").count() == steps - 1
            third.locator("button.modify").click()
            page.wait_for_selector(".proposal .note.bad", timeout=30_000)
        # accept: the team runs the plan
        page.locator('.proposal[data-generation="3"] button.accept').click()
        page.wait_for_selector('#running-plan p.running[data-problem="StackBlocks"]', timeout=30_000)
        assert page.locator(".proposal").count() == 0
        # each agent's tree shows the generated plan it runs, its current state highlighted
        page.wait_for_selector("#trees-body li.plan.generated li.state.current", timeout=30_000)
        page.fill("#filter", "operator")
        page.wait_for_function(
            "[...document.querySelectorAll('#log-body tr')].filter((tr) => !tr.hidden).length >= 3", timeout=10_000
        )
        page.fill("#filter", "")
        page.screenshot(path=str(SHOTS / "live-running.png"), full_page=True)


@pytest.fixture(scope="module")
def replan_trace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A blocks demo with an opponent that makes the team replan (in a process of its own: OMPL's seed is per process)."""
    folder = tmp_path_factory.mktemp("replan")
    command = [sys.executable, "-m", "alica.app.cli", "demo", "blocksworld", "--robots", "2", "--blocks", "4"]
    command += ["--opponents", "1", "--seed", "2", "--out", str(folder)]
    subprocess.run(command, check=True, capture_output=True, timeout=300)
    return folder / "trace.jsonl"


def test_a_replay_of_a_demo_trace_jumps_to_its_replans(replan_trace: Path) -> None:
    _browser_or_skip()
    events = [json.loads(line) for line in replan_trace.read_text(encoding="utf-8").splitlines()]
    replans = [e["t"] for e in events if e.get("event") == "replan"]
    assert replans, "the demo with an opponent replans"
    with contextlib.contextmanager(_serve)("--trace", str(replan_trace)) as url, _page(url, 1400, 1000) as page:
        page.click("#next-replan")
        page.wait_for_function(f"Math.abs(parseFloat(document.getElementById('slider').value) - {replans[0]}) < 1e-6")
        page.fill("#filter", "replan")
        page.wait_for_function("document.getElementById('log-body').rows.length >= 1", timeout=10_000)
        assert "replan" in page.locator("#log-body tr").first.inner_text()
        page.screenshot(path=str(SHOTS / "replay-replan.png"), full_page=True)
        if len(replans) > 1:
            page.click("#next-replan")
            page.wait_for_function(
                f"Math.abs(parseFloat(document.getElementById('slider').value) - {replans[1]}) < 1e-6"
            )


def test_the_live_page_of_a_team_of_processes_shows_its_agents_and_accepts_its_plan() -> None:
    _browser_or_skip()
    facts = "on(a, b) and ontable(b) and ontable(c) and clear(a) and clear(c) and handempty(r1) and handempty(r2)@0"
    team = [str(plans_dir() / "blocksworld" / "mission.yaml"), "--agents", "r1:Manipulator,r2:Manipulator"]
    team += ["--stand-ins", "--fact", facts, "--processes", "--review", "--time-limit", "60"]
    with live_run(*team) as live, _page(live.url, 1400, 1000) as page:
        page.wait_for_selector('#agents-body tr[data-agent="r1"]', timeout=20_000)
        page.wait_for_selector('#agents-body tr[data-agent="r2"]', timeout=20_000)
        page.wait_for_selector(".proposal button.accept", timeout=30_000)
        page.locator(".proposal button.accept").first.click()
        page.wait_for_selector('#running-plan p.running[data-problem="StackBlocks"]', timeout=30_000)
        page.screenshot(path=str(SHOTS / "live-processes.png"), full_page=True)
