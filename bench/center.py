"""The control center's figures (issue 21): event-to-page latency, replay page load, the live server's CPU share.

Run: ``.venv/bin/python bench/center.py [--window 30] [--agents 10] [--quick]``
(``--quick``: a 10 s window, a 2-minute replay trace, one page load).
Needs Playwright and Debian's chromium (``/usr/bin/chromium``, as
``tests/center/test_browser.py``); without them it says so and exits 0.

1. **Live latency.** ``alica run plans/blocksworld/mission.yaml --world blocks``
   with ``--agents`` manipulators (default 10) at ``--frequency 30``,
   ``--trace-messages`` (every message an event: a steady flow for as long as
   the team runs) and ``--center`` at ``--speed 1``; the live page is opened in
   headless chromium. After ``--warmup`` wall seconds the page's
   ``window.alicaLatency`` (ms from an event reaching the server's hub, wall
   clock, to the animation frame after the page drew it) is emptied, and read
   again ``--window`` wall seconds later: p50, p90, p99 and max (and the part
   until the WebSocket message reached the page: the server's share), the events per
   second the page received, the pushes (WebSocket messages) per second and
   their mean size, the page's time in its WebSocket message handler and in
   each view of ``views.js`` (wrapped by an init script), and chromium's own
   split of the renderer's main thread (CDP ``Performance.getMetrics``: script,
   layout, style; ``TaskDuration`` is all of it, paint included: near 100 %
   means the page cannot keep up and the latency grows). The team's simulated time is read from ``/api/meta`` (the hub's
   status) at both ends of the window: simulated seconds per wall second
   below 1 means the run could not keep real time.
2. **Replay page load.** 5-agent traces made by the library, all real runs:
   ``alica demo blocksworld --agents 5 --opponents 4 --blocks 8`` (the team,
   opponents that disturb the stacks, poses and blocks; it lasts as long as
   the team needs to reach the goal, about 220 simulated s with seed 0, not 10
   minutes: the table gives its length), and ``alica run
   plans/blocksworld/mission.yaml --world blocks --stacks c,f,e,d;b,g;a,h``
   with r1..r5 for ``--trace-time`` simulated seconds (default 600, ``--ticks``
   at 30 Hz: the team works for about 40 s, then its agents stay in the
   success state and keep talking), once without and once with
   ``--trace-messages``. For each:
   events, MB, ``alica center --trace``: ``page.goto`` to
   ``dataset.ready == "yes"`` (median of ``--loads`` loads, each in a fresh
   browser context), the server's time for ``/api/meta``, ``/api/events``,
   ``/api/trees`` and ``/api/state?t=`` mid-trace (median of 3, from this
   process over loopback), and a slider jump (value set and an ``input``
   event, until the agents table is redrawn and the next frame: median and
   max over 5 times across the trace).
3. **Server CPU.** The process of figure 1 (with a page) and the same run
   without a page: CPU time (user + system, ``/proc/PID/stat``) over the same
   wall window, as % of one core; per thread (``/proc/PID/task``): the main
   thread (the team) and the others (the server thread ``alica-center`` and
   whatever else the process started; Python 3.11 does not name its threads,
   so the rest is taken together); and chromium's processes (every
   descendant of this process whose command line names chromium).

Every process gets bounded waits and is stopped (terminate, then kill) in
``finally``. Progress lines go to standard error; the tables to standard output.
"""

from __future__ import annotations

import argparse
import json
import os
import selectors
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.parse
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = "/usr/bin/chromium"
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--no-first-run",
]
PLAN = "plans/blocksworld/mission.yaml"
STACKS = "c,f,e,d;b,g;a,h"
"""The blocks' start: the goal tower a on b on c needs every block moved (the team works for about 40 s)."""
TICK = os.sysconf("SC_CLK_TCK")

# Wraps the live page's WebSocket message handler and the views of views.js to time them (installed before any
# script of the page runs: views.js assigns window.AlicaViews, live.js reads it once).
INSTRUMENT = """
(() => {
  const bench = window.alicaBench = { frames: 0, bytes: 0, maxBytes: 0, handlerMs: 0, views: {}, arrival: [] };
  const add = EventTarget.prototype.addEventListener;
  WebSocket.prototype.addEventListener = function (type, fn, options) {
    if (type !== "message") { return add.call(this, type, fn, options); }
    return add.call(this, type, function (event) {
      const arrived = Date.now(), walls = JSON.parse(event.data).walls || [];
      for (const w of walls) { window.alicaBench.arrival.push(arrived - w * 1000); }
      const t0 = performance.now();
      try { return fn.call(this, event); } finally {
        const b = window.alicaBench;
        b.frames++; b.bytes += event.data.length; b.maxBytes = Math.max(b.maxBytes, event.data.length);
        b.handlerMs += performance.now() - t0;
      }
    }, options);
  };
  let views;
  Object.defineProperty(window, "AlicaViews", {
    configurable: true,
    get() { return views; },
    set(value) {
      views = {};
      for (const [name, f] of Object.entries(value)) {
        views[name] = function (...args) {
          const t0 = performance.now();
          try { return f.apply(this, args); } finally {
            const v = window.alicaBench.views; v[name] = (v[name] || 0) + performance.now() - t0;
          }
        };
      }
    },
  });
})();
"""

RESET = """() => {
  if (window.alicaLatency) { window.alicaLatency.length = 0; }
  const b = window.alicaBench; b.frames = 0; b.bytes = 0; b.maxBytes = 0; b.handlerMs = 0; b.views = {}; b.arrival = [];
}"""

# A slider jump on the replay page: ms from the input event to the frame after the agents table was redrawn.
JUMP = """async (t) => {
  const body = document.getElementById("agents-body"), slider = document.getElementById("slider");
  return await new Promise((resolve) => {
    const t0 = performance.now();
    const watch = new MutationObserver(() => {
      watch.disconnect();
      requestAnimationFrame(() => resolve(performance.now() - t0));
    });
    watch.observe(body, { childList: true });
    slider.value = String(t);
    slider.dispatchEvent(new Event("input"));
  });
}"""


def log(text: str) -> None:
    print(text, file=sys.stderr, flush=True)


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    if not ordered:
        return float("nan")
    k = min(len(ordered) - 1, max(0, round(q / 100 * (len(ordered) - 1))))
    return ordered[k]


# -- processes ------------------------------------------------------------------


class Served:
    """An ``alica`` command that prints its address line first; stopped by :meth:`stop`."""

    def __init__(self, args: list[str], timeout: float = 60.0) -> None:
        self.stderr = tempfile.TemporaryFile()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "alica.app.cli", *args],
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=self.stderr,
            text=True,
        )
        self.url = self._first_line(timeout)
        self.started = time.monotonic()
        threading.Thread(target=self._drain, daemon=True).start()  # the summary must not fill the pipe
        parts = urllib.parse.urlsplit(self.url)
        self.base = f"{parts.scheme}://{parts.netloc}/"
        self.token = urllib.parse.parse_qs(parts.query)["token"][0]

    @property
    def pid(self) -> int:
        return self.process.pid

    def _first_line(self, timeout: float) -> str:
        assert self.process.stdout is not None
        selector = selectors.DefaultSelector()
        selector.register(self.process.stdout, selectors.EVENT_READ)
        deadline = time.monotonic() + timeout
        try:
            while time.monotonic() < deadline:
                if selector.select(timeout=0.2):
                    line = self.process.stdout.readline().strip()
                    if line.startswith("http://"):
                        return line
                    if not line and self.process.poll() is not None:
                        break
                elif self.process.poll() is not None:
                    break
        finally:
            selector.close()
        self.stop()
        raise RuntimeError(f"no address line within {timeout:.0f} s: {self.errors()}")

    def _drain(self) -> None:
        assert self.process.stdout is not None
        for _ in self.process.stdout:
            pass

    def errors(self) -> str:
        self.stderr.seek(0)
        return self.stderr.read().decode(errors="replace")[-2000:]

    def get(self, path: str, timeout: float = 60.0) -> tuple[float, bytes]:
        """GET ``path`` with the token: (seconds, body)."""
        sep = "&" if "?" in path else "?"
        start = time.perf_counter()
        with urllib.request.urlopen(f"{self.base}{path}{sep}token={self.token}", timeout=timeout) as answer:
            body = answer.read()
        return time.perf_counter() - start, body

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(timeout=10)
        self.stderr.close()


def run_bounded(args: list[str], timeout: float) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "alica.app.cli", *args], cwd=ROOT, capture_output=True, text=True, timeout=timeout
    )


# -- CPU from /proc -------------------------------------------------------------


def cpu_of(stat_path: str) -> float:
    """CPU seconds (user + system) from a ``/proc/.../stat`` file (0 when it is gone)."""
    try:
        with open(stat_path) as handle:
            text = handle.read()
    except OSError:
        return 0.0
    fields = text[text.rindex(")") + 2 :].split()
    return (int(fields[11]) + int(fields[12])) / TICK


def threads_cpu(pid: int) -> dict[int, float]:
    try:
        tids = [int(t) for t in os.listdir(f"/proc/{pid}/task")]
    except OSError:
        return {}
    return {tid: cpu_of(f"/proc/{pid}/task/{tid}/stat") for tid in tids}


def browser_pids() -> list[int]:
    """Every descendant of this process whose command line names chromium."""
    parents: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as handle:
                    text = handle.read()
                parents[int(entry)] = int(text[text.rindex(")") + 2 :].split()[1])
            except (OSError, ValueError):
                continue
    mine = {os.getpid()}
    grew = True
    while grew:
        grew = False
        for child, parent in parents.items():
            if parent in mine and child not in mine:
                mine.add(child)
                grew = True
    found = []
    for pid in mine - {os.getpid()}:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as handle:
                if b"chromium" in handle.read():
                    found.append(pid)
        except OSError:
            continue
    return found


@dataclass
class CpuSample:
    wall: float
    process: float
    threads: dict[int, float]
    browser: dict[int, float]

    @classmethod
    def take(cls, pid: int, browser: list[int]) -> CpuSample:
        return cls(
            time.monotonic(),
            cpu_of(f"/proc/{pid}/stat"),
            threads_cpu(pid),
            {b: cpu_of(f"/proc/{b}/stat") for b in browser},
        )


@dataclass
class Cpu:
    """CPU % of one core over a window."""

    process: float
    main: float
    others: float
    browser: float | None
    threads: int

    @classmethod
    def between(cls, pid: int, a: CpuSample, b: CpuSample) -> Cpu:
        wall = b.wall - a.wall
        main = b.threads.get(pid, 0.0) - a.threads.get(pid, 0.0)
        others = sum(b.threads[t] - a.threads.get(t, 0.0) for t in b.threads if t != pid)
        browser = sum(b.browser[p] - a.browser.get(p, 0.0) for p in b.browser) if b.browser else None
        return cls(
            100 * (b.process - a.process) / wall,
            100 * main / wall,
            100 * others / wall,
            None if browser is None else 100 * browser / wall,
            len(b.threads),
        )


# -- 1 and 3: the live team -----------------------------------------------------


@dataclass
class Live:
    page: bool
    latencies: list[float] = field(default_factory=list)
    wall: float = 0.0
    sim: float = 0.0
    running_at_end: bool = True
    events: int = 0
    bench: dict[str, Any] = field(default_factory=dict)
    metrics: dict[str, float] = field(default_factory=dict)
    cpu: Cpu | None = None
    snapshot_bytes: int = 0
    error: str | None = None


def live_command(args: argparse.Namespace) -> list[str]:
    agents = ",".join(f"r{i}:Manipulator" for i in range(1, args.agents + 1))
    ticks = 30 * (args.warmup + args.window + 60)  # the team runs on after the window, done or not
    return [
        "run",
        PLAN,
        "--world",
        "blocks",
        "--stacks",
        STACKS,
        "--agents",
        agents,
        "--seed",
        str(args.seed),
        "--frequency",
        "30",
        "--trace-messages",
        "--ticks",
        str(int(ticks)),
        "--center",
        "--center-port",
        "0",
        "--speed",
        "1",
    ]


def hub_status(served: Served) -> dict[str, Any]:
    return dict(json.loads(served.get("api/meta", timeout=10)[1])["status"])


def live_run(args: argparse.Namespace, with_page: bool, playwright: Any) -> Live:
    out = Live(with_page)
    served = Served(live_command(args))
    browser = context = None
    try:
        page = None
        if with_page:
            browser = playwright.chromium.launch(executable_path=CHROMIUM, args=ARGS)
            context = browser.new_context(viewport={"width": 1400, "height": 1000})
            context.add_init_script(INSTRUMENT)
            page = context.new_page()
            page.goto(served.url, timeout=30_000)
            page.wait_for_function("document.body.dataset.ready === 'yes'", timeout=30_000)
            cdp = context.new_cdp_session(page)
            cdp.send("Performance.enable")
        chromium = browser_pids() if with_page else []
        wait = served.started + args.warmup - time.monotonic()
        if wait > 0:
            if page is not None:
                page.wait_for_timeout(wait * 1000)
            else:
                time.sleep(wait)  # the no-page run waits as long as the page run does
        before = hub_status(served)
        if page is not None:
            page.evaluate(RESET)
            metrics0 = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
        start = CpuSample.take(served.pid, chromium)
        if page is not None:
            page.wait_for_timeout(args.window * 1000)
        else:
            time.sleep(args.window)
        end = CpuSample.take(served.pid, chromium)
        after = hub_status(served)
        if page is not None:
            out.latencies = [float(v) for v in page.evaluate("() => window.alicaLatency.slice()")]
            out.bench = page.evaluate("() => window.alicaBench")
            metrics1 = {m["name"]: m["value"] for m in cdp.send("Performance.getMetrics")["metrics"]}
            out.metrics = {k: metrics1[k] - metrics0.get(k, 0.0) for k in metrics1 if k.endswith("Duration")}
        out.cpu = Cpu.between(served.pid, start, end)
        out.wall = end.wall - start.wall
        out.sim = float(after["t"]) - float(before["t"])
        out.running_at_end = bool(after["running"])
        out.snapshot_bytes = len(served.get("api/state", timeout=10)[1])
        out.events = len(out.latencies)
    except Exception as exc:  # reported under the tables
        out.error = f"{type(exc).__name__}: {exc}"
    finally:
        if context is not None:
            context.close()
        if browser is not None:
            browser.close()
        served.stop()
    return out


# -- 2: the replay --------------------------------------------------------------


@dataclass
class Replay:
    label: str
    events: int = 0
    mb: float = 0.0
    duration: float = 0.0
    load: float = float("nan")
    api: dict[str, float] = field(default_factory=dict)
    api_mb: dict[str, float] = field(default_factory=dict)
    jump: list[float] = field(default_factory=list)
    views: dict[str, float] = field(default_factory=dict)
    """ms per slider jump in each view of views.js"""
    error: str | None = None


def make_demo_trace(path: Path, agents: int, timeout: float) -> None:
    with tempfile.TemporaryDirectory() as out:
        args = ["demo", "blocksworld", "--robots", str(agents), "--opponents", "4", "--blocks", "8", "--seed", "0"]
        start = time.monotonic()
        result = run_bounded([*args, "--out", out, "--no-progress"], timeout)
        made = Path(out) / "trace.jsonl"
        if not made.exists():
            raise RuntimeError(f"no trace written (exit {result.returncode}): {result.stderr[-1000:]}")
        shutil.copyfile(made, path)
    log(f"  trace {path.name}: exit {result.returncode} in {time.monotonic() - start:.0f} s wall")


def make_trace(path: Path, agents: int, seconds: float, messages: bool, timeout: float) -> None:
    names = ",".join(f"r{i}:Manipulator" for i in range(1, agents + 1))
    args = [
        "run",
        PLAN,
        "--world",
        "blocks",
        "--agents",
        names,
        "--stacks",
        STACKS,
        "--seed",
        "0",
        "--ticks",
        str(int(30 * seconds)),
        "--trace",
        str(path),
    ]
    if messages:
        args.append("--trace-messages")
    start = time.monotonic()
    result = run_bounded(args, timeout)
    if not path.exists():
        raise RuntimeError(f"no trace written (exit {result.returncode}): {result.stderr[-1000:]}")
    log(f"  trace {path.name}: exit {result.returncode} in {time.monotonic() - start:.0f} s wall")


def replay_run(label: str, trace: Path, args: argparse.Namespace, playwright: Any) -> Replay:
    out = Replay(label)
    lines = trace.read_text().splitlines()
    out.events = len(lines) - 1  # the header
    out.mb = trace.stat().st_size / 1e6
    served = Served(["center", "--trace", str(trace), "--port", "0"], timeout=120)
    browser = None
    try:
        meta = json.loads(served.get("api/meta")[1])
        out.duration = float(meta["duration"])
        mid = float(meta["start"]) + out.duration / 2
        for name, path in [
            ("meta", "api/meta"),
            ("events", "api/events"),
            ("trees", "api/trees"),
            ("state", f"api/state?t={mid}"),
        ]:
            times = []
            for _ in range(3):
                seconds, body = served.get(path)
                times.append(seconds)
            out.api[name] = statistics.median(times)
            out.api_mb[name] = len(body) / 1e6
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        loads = []
        page = context = None
        for _ in range(args.loads):
            if context is not None:
                context.close()
            context = browser.new_context(viewport={"width": 1400, "height": 1000})
            context.add_init_script(INSTRUMENT)
            page = context.new_page()
            start = time.perf_counter()
            page.goto(served.url, timeout=120_000)
            page.wait_for_function("document.body.dataset.ready === 'yes'", timeout=120_000, polling=10)
            loads.append(time.perf_counter() - start)
        out.load = statistics.median(loads)
        assert page is not None
        page.evaluate(RESET)
        fractions = (0.1, 0.3, 0.5, 0.7, 0.9)
        for fraction in fractions:
            t = float(meta["start"]) + fraction * out.duration
            out.jump.append(float(page.evaluate(JUMP, t)))
        views = page.evaluate("() => window.alicaBench.views")
        out.views = {name: float(ms) / len(fractions) for name, ms in views.items()}
        if context is not None:
            context.close()
    except Exception as exc:  # reported under the tables
        out.error = f"{type(exc).__name__}: {exc}"
    finally:
        if browser is not None:
            browser.close()
        served.stop()
    return out


# -- the tables -----------------------------------------------------------------


def live_table(run: Live, agents: int) -> None:
    print(
        f"### 1. Event to page, {agents} agents at 30 Hz, --trace-messages, speed 1 (live page in headless chromium)\n"
    )
    if run.error:
        print(f"run failed: {run.error}\n")
        return
    lat = run.latencies
    b = run.bench
    arrival = [float(v) for v in b.get("arrival", [])]
    frames = max(int(b.get("frames", 0)), 1)
    print("| figure | value |")
    print("| --- | ---: |")
    rows = [
        ("window (wall s)", f"{run.wall:.1f}"),
        ("simulated s per wall s (1 = real time)", f"{run.sim / run.wall:.2f}"),
        ("team still running at the end", "yes" if run.running_at_end else "no (the flow stopped)"),
        ("events received by the page", f"{len(lat)}"),
        ("events / s", f"{len(lat) / run.wall:.0f}"),
        ("latency p50 (ms)", f"{percentile(lat, 50):.0f}"),
        ("latency p90 (ms)", f"{percentile(lat, 90):.0f}"),
        ("latency p99 (ms)", f"{percentile(lat, 99):.0f}"),
        ("latency max (ms)", f"{max(lat) if lat else float('nan'):.0f}"),
        (
            "of which hub -> message at the page (server and socket) p50 / p99 / max (ms)",
            f"{percentile(arrival, 50):.0f} / {percentile(arrival, 99):.0f} / {max(arrival, default=float('nan')):.0f}",
        ),
        ("pushes (WebSocket messages) / s", f"{b.get('frames', 0) / run.wall:.1f}"),
        ("events per push (mean)", f"{len(lat) / frames:.1f}"),
        ("push size mean / max (kB)", f"{b.get('bytes', 0) / frames / 1e3:.1f} / {b.get('maxBytes', 0) / 1e3:.1f}"),
        ("of which the state snapshot (kB, /api/state after the window)", f"{run.snapshot_bytes / 1e3:.1f}"),
        ("page: WebSocket message handler, ms per push", f"{b.get('handlerMs', 0) / frames:.2f}"),
    ]
    for name, ms in sorted(b.get("views", {}).items(), key=lambda kv: -kv[1]):
        rows.append((f"page: views.{name}, ms per wall s", f"{ms / run.wall:.1f}"))
    for name in ("ScriptDuration", "LayoutDuration", "RecalcStyleDuration", "TaskDuration"):
        if name in run.metrics:
            rows.append(
                (f"chromium renderer main thread: {name} (% of wall)", f"{100 * run.metrics[name] / run.wall:.0f}")
            )
    for name, value in rows:
        print(f"| {name} | {value} |")
    print()


def replay_table(runs: list[Replay], agents: int, loads: int) -> None:
    print(f"### 2. Replay page load, {agents}-agent traces (real runs; see the labels)\n")
    print(
        "| trace | simulated s | events | MB | goto -> ready (s, median of "
        f"{loads}) | /api/meta (ms) | /api/events (ms, MB) | /api/trees (ms) | /api/state?t=mid (ms) "
        "| slider jump median / max (ms) | views.js per jump (ms) |"
    )
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    for r in runs:
        if r.error:
            print(f"| {r.label} | {r.duration:.0f} | {r.events} | {r.mb:.1f} | failed: {r.error} | | | | | | |")
            continue
        views = ", ".join(f"{name} {ms:.0f}" for name, ms in sorted(r.views.items(), key=lambda kv: -kv[1]))
        print(
            f"| {r.label} | {r.duration:.0f} | {r.events} | {r.mb:.1f} | {r.load:.2f} | {1000 * r.api['meta']:.0f} "
            f"| {1000 * r.api['events']:.0f} ({r.api_mb['events']:.1f}) | {1000 * r.api['trees']:.0f} "
            f"| {1000 * r.api['state']:.0f} | {statistics.median(r.jump):.0f} / {max(r.jump):.0f} | {views} |"
        )
    print()


def cpu_table(with_page: Live, without: Live, agents: int) -> None:
    print(f"### 3. CPU of the `alica run --center` process, {agents} agents, % of one core over the same window\n")
    if with_page.cpu is None or without.cpu is None:
        print(f"run failed: {with_page.error or without.error}\n")
        return
    a, b = without.cpu, with_page.cpu
    print("| | no page | one page | difference (serving cost) |")
    print("| --- | ---: | ---: | ---: |")
    print(f"| whole process | {a.process:.0f} | {b.process:.0f} | {b.process - a.process:+.0f} |")
    print(f"| main thread (the team) | {a.main:.0f} | {b.main:.0f} | {b.main - a.main:+.0f} |")
    print(
        f"| other threads (server thread alica-center and the rest; {a.threads} / {b.threads} threads) "
        f"| {a.others:.0f} | {b.others:.0f} | {b.others - a.others:+.0f} |"
    )
    print(f"| simulated s per wall s | {without.sim / without.wall:.2f} | {with_page.sim / with_page.wall:.2f} | |")
    browser = "-" if b.browser is None else f"{b.browser:.0f}"
    print(f"| chromium (all its processes) | - | {browser} | |")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", type=int, default=10, help="agents of the live team (figures 1 and 3)")
    parser.add_argument("--window", type=float, default=30.0, help="wall seconds measured on the live team")
    parser.add_argument("--warmup", type=float, default=8.0, help="wall seconds after start before the window")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--trace-time", type=float, default=600.0, help="simulated seconds of the replay traces")
    parser.add_argument("--trace-agents", type=int, default=5)
    parser.add_argument("--loads", type=int, default=3, help="page loads of each replay (median)")
    parser.add_argument("--traces", metavar="DIR", help="keep the replay traces here (reused when present)")
    parser.add_argument("--skip", default="", help="figures to leave out, comma-separated: live,replay,cpu")
    parser.add_argument("--quick", action="store_true", help="10 s window, 120 s traces, one load")
    args = parser.parse_args()
    if args.quick:
        args.window, args.trace_time, args.loads, args.warmup = 10.0, 120.0, 1, 5.0
    skip = set(filter(None, args.skip.split(",")))
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        print("skipped: the playwright package is not installed (make setup installs it)")
        return
    if shutil.which(CHROMIUM) is None:
        print(f"skipped: no browser at {CHROMIUM}: install Debian's chromium package (apt-get install chromium)")
        return

    print(f"machine: {os.cpu_count()} CPUs, Python {sys.version.split()[0]}\n")
    with sync_playwright() as playwright:
        with_page = without = None
        if not {"live", "cpu"} <= skip:
            log(f"live team of {args.agents} with a page: {args.warmup:.0f} + {args.window:.0f} s")
            with_page = live_run(args, True, playwright)
            live_table(with_page, args.agents)
        if "cpu" not in skip:
            log("the same team without a page")
            without = live_run(args, False, playwright)
            assert with_page is not None
            cpu_table(with_page, without, args.agents)
        if "replay" not in skip:
            folder = Path(args.traces) if args.traces else Path(tempfile.mkdtemp(prefix="bench-center-"))
            folder.mkdir(parents=True, exist_ok=True)
            runs = []
            n, seconds = args.trace_agents, args.trace_time
            try:
                demo = folder / f"demo{n}-o4-b8.jsonl"
                if not demo.exists():
                    log("making the demo trace")
                    make_demo_trace(demo, n, timeout=1800)
                log(f"replay of {demo.name}")
                runs.append(replay_run(f"demo blocksworld, {n} agents + 4 opponents, 8 blocks", demo, args, playwright))
                for messages in (False, True):
                    label = f"alica run, {n} agents, --ticks {int(30 * seconds)}" + (
                        ", --trace-messages" if messages else ""
                    )
                    trace = folder / f"run{n}-{int(seconds)}s-{'msgs' if messages else 'plain'}.jsonl"
                    if not trace.exists():
                        log(f"making the trace: {label}")
                        make_trace(trace, n, seconds, messages, timeout=1800)
                    log(f"replay of {trace.name}")
                    runs.append(replay_run(label, trace, args, playwright))
            finally:
                if not args.traces:
                    shutil.rmtree(folder, ignore_errors=True)
            replay_table(runs, args.trace_agents, args.loads)
    for run in (with_page, without):
        if run is not None and run.error:
            print(f"error ({'page' if run.page else 'no page'}): {run.error}")


if __name__ == "__main__":
    main()
