"""The replay page's views in headless Chromium: the agents table, the map's labels and scale bar, the event log.

Uses the browser helpers of ``test_browser.py`` (skipped, saying why, without Playwright or Chromium);
screenshots go to ``build/center/`` (``agents_table.png``, ``map_labels.png``, ``log.png``).
"""

from __future__ import annotations

import contextlib
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.center.test_browser import SHOTS, _browser_or_skip, _page, _serve, _slide_to

pytestmark = pytest.mark.optional

LONG_PLAN = "GetObjects_g1v1_amparo_dfab8f_with_a_long_generated_name"


def _write(path: Path, events: list[dict[str, Any]]) -> Path:
    path.write_text("".join(json.dumps(e) + "\n" for e in events), encoding="utf-8")
    return path


def _header(agents: dict[str, str], **fields: Any) -> dict[str, Any]:
    return {
        "t": 0.0,
        "agent": "-",
        "event": "trace",
        "format": "alica-trace",
        "version": 2,
        "agents": {a: {"role": r, "plan": "Top"} for a, r in agents.items()},
        **fields,
    }


@contextlib.contextmanager
def _replay(trace: Path, width: int, height: int) -> Iterator[Any]:
    _browser_or_skip()
    with contextlib.contextmanager(_serve)("--trace", str(trace)) as url, _page(url, width, height) as page:
        yield page


@pytest.fixture()
def crowded_trace(tmp_path: Path) -> Path:
    """Four robots and three samples within a metre of each other on a 20 m field, agents in long-named plans."""
    agents = {"scout": "Scout", "stummel": "Stummel", "amparo": "Amparo", "rover_with_a_long_name": "Scout"}
    events: list[dict[str, Any]] = [_header(agents, world="lunar", bounds=[-10.0, -10.0, 10.0, 10.0])]
    for i, name in enumerate(agents):
        key = f"Top/Collect/{LONG_PLAN}"
        events.append(
            {
                "t": 0.0,
                "agent": name,
                "event": "allocation",
                "key": key,
                "plan": LONG_PLAN,
                "entries": {name: "T0_S0_MoveToObject"},
            }
        )
        events.append(
            {
                "t": 0.0,
                "agent": name,
                "event": "behaviour",
                "key": key,
                "behaviour": "GoToDroppedSampleAndWaitForTheOthers",
                "status": "running",
            }
        )
        events.append(
            {
                "t": 0.5,
                "agent": name,
                "event": "pose",
                "x": 1.0 + 0.2 * i,
                "y": 1.0 + 0.15 * (i % 2),
                "yaw": 0.3,
                "alive": True,
            }
        )
    for i, kind in enumerate(["green-black-green", "green-white-red", "red-black-red"]):
        name = f"s{i}"
        events.append(
            {
                "t": 0.5,
                "agent": "-",
                "event": "object",
                "name": name,
                "kind": "sample",
                "sample_kind": kind,
                "x": 1.1 + 0.25 * i,
                "y": 0.8,
                "z": 0.0,
                "radius": 0.05,
            }
        )
        events.append(
            {
                "t": 0.6,
                "agent": "-",
                "event": "found",
                "name": f"found_{name}",
                "kind": kind,
                "x": 1.1 + 0.25 * i,
                "y": 0.8,
            }
        )
    key = f"Top/Collect/{LONG_PLAN}"
    events.append(
        {
            "t": 1.0,
            "agent": "scout",
            "event": "transition",
            "key": key,
            "plan": LONG_PLAN,
            "source": "Explore",
            "target": "Return",
        }
    )
    return _write(tmp_path / "crowded.jsonl", events)


def _overlaps(boxes: list[dict[str, float]], slack: float = 0.5) -> list[tuple[int, int]]:
    bad = []
    for i, a in enumerate(boxes):
        for j, b in enumerate(boxes[:i]):
            if (
                min(a["right"], b["right"]) - max(a["left"], b["left"]) > slack
                and min(a["bottom"], b["bottom"]) - max(a["top"], b["top"]) > slack
            ):
                bad.append((j, i))
    return bad


RECTS = "(els) => els.map((e) => { const r = e.getBoundingClientRect(); return {left: r.left, right: r.right, top: r.top, bottom: r.bottom}; })"


@pytest.mark.parametrize("width", [800, 1280])
def test_the_agents_table_shows_every_column_whole(crowded_trace: Path, width: int) -> None:
    with _replay(crowded_trace, width, 900) as page:
        _slide_to(page, "1")
        page.wait_for_function("document.getElementById('time').textContent === 't = 1.000 s'", timeout=10_000)
        section = page.locator("#agents").bounding_box()
        assert section is not None
        cells = page.locator("#agents th, #agents-body td")
        assert cells.count() == 7 * 5
        for box in cells.evaluate_all(RECTS):
            assert box["right"] <= section["x"] + section["width"] + 0.5, (width, box, section)
        overflowing = cells.evaluate_all(
            "(els) => els.filter((e) => e.scrollWidth > e.clientWidth + 1).map((e) => e.textContent)"
        )
        assert overflowing == []
        row = page.locator('#agents-body tr[data-agent="scout"] td')
        assert row.nth(4).inner_text().replace("\n", "") == LONG_PLAN  # wrapped, not cut
        assert row.nth(5).inner_text() == "Return"
        if width == 800:
            page.locator("#agents").screenshot(path=str(SHOTS / "agents_table.png"))


def test_the_state_column_shows_the_entry_state_before_the_first_transition(recorded_trace: Path) -> None:
    with _replay(recorded_trace, 1280, 800) as page:
        assert page.locator("#slider").input_value() == "0"
        states = page.locator("#agents-body td:nth-child(6)").all_inner_texts()
        assert states == ["TakeSpot", "TakeSpot", "TakeSpot"]  # the formation's entry point, no transition yet


def test_map_labels_do_not_overlap_and_moved_ones_have_leader_lines(crowded_trace: Path) -> None:
    with _replay(crowded_trace, 1280, 900) as page:
        _slide_to(page, "1")
        page.wait_for_function("document.querySelectorAll('#map-body svg text.label').length === 7", timeout=10_000)
        labels = page.locator("#map-body svg text.label")
        texts = sorted(labels.all_text_contents())
        assert texts[:3] == ["amparo", "rover_with_a_long_name", "s0: green-black-green"]
        boxes = labels.evaluate_all(RECTS)
        assert _overlaps(boxes) == []
        field = page.locator("#map-body svg rect.field").evaluate(RECTS.replace("(els) => els.map", "(e) => [e].map"))[
            0
        ]
        for box in boxes:
            assert field["left"] - 0.5 <= box["left"] and box["right"] <= field["right"] + 0.5
            assert field["top"] - 0.5 <= box["top"] and box["bottom"] <= field["bottom"] + 0.5
        moved = page.locator('#map-body svg text.label[data-moved="yes"]').count()
        assert moved >= 1 and page.locator("#map-body svg line.leader").count() == moved
        page.locator("#map").screenshot(path=str(SHOTS / "map_labels.png"))


def test_label_placement_keeps_labels_apart(crowded_trace: Path) -> None:
    with _replay(crowded_trace, 1000, 700) as page:
        boxes = page.evaluate(
            "() => window.AlicaViews.placeLabels(Array.from({length: 12}, () => ({ax: 5, ay: 5, r: 0.2, w: 2, h: 0.6})))"
            ".map((b) => ({left: b.x, right: b.x + b.w, top: b.y, bottom: b.y + b.h}))"
        )
        assert len(boxes) == 12 and _overlaps(boxes, slack=1e-9) == []
        inside = page.evaluate(
            "() => window.AlicaViews.placeLabels([{ax: 9.9, ay: 0.1, r: 0.1, w: 3, h: 1}], {x: 0, y: 0, w: 10, h: 10})[0]"
        )
        assert inside["x"] >= 0 and inside["x"] + 3 <= 10 and inside["y"] >= 0  # kept on the field


def test_the_map_has_a_scale_bar_in_metres(crowded_trace: Path) -> None:
    with _replay(crowded_trace, 1280, 900) as page:
        lengths = page.evaluate("() => [14, 20, 40, 0.3, 1000].map(window.AlicaViews.scaleLength)")
        assert lengths == [2, 2, 5, 0.05, 200]
        _slide_to(page, "1")
        bar = page.locator("#map-body svg g.scale-bar")
        bar.wait_for(timeout=10_000)
        assert bar.get_attribute("data-metres") == "2" and bar.locator("text").text_content() == "2 m"
        rect = (
            "(e) => { const r = e.getBoundingClientRect(); return r.right - r.left; }"  # the geometry, not the stroke
        )
        drawn = bar.locator("path.bar").evaluate(rect)
        field = page.locator("#map-body svg rect.field").evaluate(rect)
        assert drawn / field == pytest.approx(2 / 20, rel=0.02), (drawn, field)  # 2 m of the 20 m field


def test_the_log_shows_events_as_lines_and_hides_poses_and_map_payloads(lunar_trace: Path) -> None:
    with _replay(lunar_trace, 1280, 1000) as page:
        text = page.evaluate(
            "() => window.AlicaViews.eventText({t: 12.3, agent: 'scout', event: 'transition', key: 'M', plan: 'Mission', "
            "source: 'Explore', target: 'Return', name: 'x'})"
        )
        assert text == "  12.30 s  scout     transition Explore -> Return in Mission"
        _slide_to(page, "max")
        # the log is drawn once the state at the new time arrives (a fetch): wait for every event but poses and the header,
        # the newest 500 at most (the rows of the start time, drawn before, are fewer)
        events = [json.loads(line) for line in lunar_trace.read_text(encoding="utf-8").splitlines() if line.strip()]
        expected = min(500, sum(1 for e in events if e["event"] not in ("pose", "trace")))  # not the header either
        page.wait_for_function(f"document.querySelectorAll('#log-body tr.past').length === {expected}", timeout=10_000)
        rows = page.locator("#log-body tr.past")
        kinds = set(rows.evaluate_all("(rs) => rs.map((r) => r.dataset.kind)"))
        assert "pose" not in kinds and {"transition", "map"} <= kinds
        lines = rows.all_inner_texts()
        assert all(re.match(r"^\s*\d+\.\d\d s  \S+\s+\S", line) for line in lines), lines[:5]
        assert max(len(line) for line in lines) < 300  # no base64 blob
        maps = page.locator('#log-body tr[data-kind="map"]').first.inner_text()
        assert re.search(r"map \d+ x \d+ cells of [\d.]+ m", maps) and "cells=" not in maps
        assert any(re.search(r"transition \w+ -> \w+ in \w+", line) for line in lines)
        page.locator("#log").screenshot(path=str(SHOTS / "log.png"))
        page.check("#raw")
        page.wait_for_selector('#log-body tr[data-kind="pose"]', timeout=10_000)
        raw_map = page.locator('#log-body tr[data-kind="map"]').first.inner_text()
        assert "cells=" in raw_map and len(raw_map) > 300  # the payload, on demand
        page.uncheck("#raw")
        page.wait_for_function("!document.querySelector('#log-body tr[data-kind=\"pose\"]')", timeout=10_000)
