// The live page: a WebSocket brings a running team's events and state; the operator sets goals and facts,
// accepts, declines or changes the plans the leader proposes, and reloads the plan files. The plan trees follow
// a reload: when the state says the hub serves another library's trees (state.plans), they are fetched again.
"use strict";
(function () {
  const $ = (id) => document.getElementById(id);
  const V = window.AlicaViews;
  const MAX_LOG = 500;
  const PAINT_MS = 50;  // the page is drawn at most 20 times a second
  let meta = null, state = null, trees = null, count = 0, fetchingTrees = false;
  const events = [], tracks = {}, edits = {};
  let proposals = {}, running = {}, checkSeq = 0;
  let queued = [], queuedWalls = [], painting = false, lastPaint = 0;  // events (and their hub wall times) not drawn yet
  window.alicaLatency = [];  // ms from an event reaching the server's hub to the page showing it (the bench reads it)

  async function call(path, payload) {
    const response = await fetch(path, {
      method: payload === undefined ? "GET" : "POST",
      credentials: "same-origin",
      headers: { "Content-Type": "application/json" },
      body: payload === undefined ? undefined : JSON.stringify(payload),
    });
    return { status: response.status, body: await response.json() };
  }

  function el(tag, attrs, text) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) { node.setAttribute(k, v); }
    if (text !== undefined) { node.textContent = text; }
    return node;
  }

  // -- what the events say ---------------------------------------------------

  function take(e) {
    events.push(e);
    if (e.event === "pose" && typeof e.x === "number") { (tracks[e.agent] = tracks[e.agent] || []).push([e.t, e.x, e.y]); }
    if (e.event === "proposal") { edits[e.problem] = { order: e.steps.map((_, i) => i), pins: {} }; }
  }

  function showStatus() {
    const s = state && state.status;
    if (!s) { return; }
    let text = "t = " + Number(state.t || 0).toFixed(2) + " s, ";
    if (s.running) { text += "running"; }
    else if (s.summary) { text += "over: " + (s.summary.success ? "success" : "not successful"); }
    $("status").textContent = text;
    $("status").dataset.running = s.running ? "yes" : "no";
  }

  // The log's rows, newest first: each event as a line of text (V.eventText); pose events only with "raw".
  function logRow(e, raw, filter) {
    const tr = V.logRow(e, raw);
    tr.dataset.line = (e.event + " " + tr.textContent).toLowerCase();
    if (filter && !tr.dataset.line.includes(filter)) { tr.hidden = true; }
    return tr;
  }

  function showLog(fresh) {
    const filter = $("filter").value.trim().toLowerCase(), raw = $("raw").checked;
    const body = $("log-body");
    for (const e of fresh) {
      if (V.logged(e, raw)) { body.prepend(logRow(e, raw, filter)); }
    }
    while (body.children.length > MAX_LOG) { body.removeChild(body.lastChild); }
  }

  // The raw toggle changed: the latest MAX_LOG rows again from the events kept.
  function relog() {
    const filter = $("filter").value.trim().toLowerCase(), raw = $("raw").checked;
    const rows = [];
    for (let i = events.length - 1; i >= 0 && rows.length < MAX_LOG; i--) {
      if (V.logged(events[i], raw)) { rows.push(logRow(events[i], raw, filter)); }
    }
    $("log-body").replaceChildren(...rows);
  }

  function refilter() {
    const filter = $("filter").value.trim().toLowerCase();
    for (const tr of $("log-body").children) { tr.hidden = Boolean(filter) && !tr.dataset.line.includes(filter); }
  }

  // What each view last drew: a view is drawn again only when what it shows changed. Under a flow of message
  // events most updates change the time alone, and the plan trees cost the most to draw.
  const drawn = {};
  function changed(view, what) {
    const key = JSON.stringify(what);
    if (drawn[view] === key) { return false; }
    drawn[view] = key;
    return true;
  }

  function draw() {
    proposals = state.operator.proposals;
    running = state.operator.running;
    showStatus();
    const plans = {};  // the agents without their poses: what the agents table and the plan trees show
    for (const [name, a] of Object.entries(state.agents || {})) { plans[name] = Object.assign({}, a, { pose: null }); }
    const agentsChanged = changed("agents", plans);
    if (agentsChanged) { V.agents($("agents-body"), state); }
    const trackCount = Object.values(tracks).reduce((n, list) => n + list.length, 0);
    if (changed("map", [state.agents, state.objects, state.map, state.bounds, trackCount])) {
      V.map($("map-body"), state, tracks, meta);
    }
    if (state.world === "blocks" && changed("blocks", state.objects)) { V.blocks($("blocks-body"), state, meta); }
    if (trees && (agentsChanged || !drawn.trees)) { V.trees($("trees-body"), state, trees); drawn.trees = true; }
    showPlans();
    showProposals();
  }

  // The library whose trees the hub serves; when it is another than the trees drawn (a reload was adopted),
  // the trees are fetched again and drawn at once.
  function showPlans() {
    const served = state.plans;
    $("plans").textContent = served ? "plans " + served : "";
    if (!served || !trees || trees.plans === served || fetchingTrees) { return; }
    fetchingTrees = true;
    call("api/trees").then((answer) => {
      if (answer.status === 200) {
        trees = answer.body;
        drawn.trees = false;
        $("trees-body").dataset.plans = trees.plans || "";
        if (state) { V.trees($("trees-body"), state, trees); drawn.trees = true; }
      }
    }).finally(() => { fetchingTrees = false; });
  }

  // -- the operator ----------------------------------------------------------

  function note(text, bad) {
    $("operator-note").textContent = text;
    $("operator-note").className = bad ? "note bad" : "note";
  }

  async function checkGoal() {
    const seq = ++checkSeq, text = $("goal").value;
    const answer = (await call("api/check", { problem: $("problem").value, goal: text })).body;
    if (seq !== checkSeq) { return; }
    const box = $("goal-check");
    $("set-goal").disabled = !answer.ok;
    if (answer.ok) {
      box.className = "check ok";
      box.textContent = "ok: " + answer.literals.join(", ");
    } else {
      box.className = "check bad";
      const col = Math.max(1, answer.column || 1);
      box.textContent = text + "\n" + " ".repeat(col - 1) + "^ column " + col + ": " + answer.error +
        (answer.hint ? "\n" + answer.hint : "");
    }
    box.dataset.column = answer.ok ? "" : String(answer.column);
  }

  async function setGoal() {
    const answer = await call("api/goal", { problem: $("problem").value, goal: $("goal").value });
    note(answer.body.ok ? "goal set: the leader plans" : "refused: " + answer.body.error, !answer.body.ok);
  }

  async function setFacts() {
    const answer = await call("api/facts", { facts: $("facts").value });
    note(answer.body.ok ? "facts set" : "refused: " + (answer.body.error || "") +
      (answer.body.column ? " (column " + answer.body.column + ")" : ""), !answer.body.ok);
  }

  async function decide(problem, action) {
    const p = proposals[problem], edit = edits[problem];
    const payload = { problem: problem, generation: p.generation, action: action };
    if (action === "modify") { payload.order = edit.order; payload.pins = edit.pins; }
    const answer = await call("api/decide", payload);
    note(answer.body.ok ? action + " sent for generation " + p.generation : "refused: " + answer.body.error,
      !answer.body.ok);
  }

  // The reload action: the plan files are loaded again; the page shows the new library's digest, or the errors
  // with file, line and column (the team then goes on with the plans it runs).
  async function reloadPlans() {
    const box = $("reload-result");
    $("reload").disabled = true;
    try {
      const answer = await call("api/reload", {});
      const result = answer.body.result || {};
      box.hidden = false;
      if (!answer.body.ok) {
        box.className = "check bad";
        box.textContent = "not reloaded: " + answer.body.error;
      } else if (result.ok) {
        box.className = "check ok";
        box.textContent = (result.digest ? "plans " + result.digest + " loaded" : "reload sent") +
          (result.sent ? " (sent to " + result.sent.join(", ") + ")" : "") +
          ": the team switches to them at one tick once every agent has them";
      } else {
        box.className = "check bad";
        box.textContent = "the plan files do not load; the team goes on with the plans it runs:\n" +
          (result.errors || []).join("\n");
      }
      box.dataset.outcome = answer.body.ok ? (result.ok ? "ok" : "invalid") : "refused";
    } finally {
      $("reload").disabled = false;
    }
  }

  function move(problem, at, by) {
    const order = edits[problem].order, to = at + by;
    if (to < 0 || to >= order.length) { return; }
    [order[at], order[to]] = [order[to], order[at]];
    showProposals(true);
  }

  function stepRow(problem, p, position, index) {
    const li = el("li", { "data-step": String(index) });
    const keep = el("input", { type: "checkbox", "aria-label": "keep step " + index });
    keep.checked = true;
    keep.addEventListener("change", () => {
      const order = edits[problem].order;
      order.splice(order.indexOf(index), 1);
      showProposals(true);
    });
    const up = el("button", { type: "button", class: "up", title: "earlier" }, "\u2191");
    const down = el("button", { type: "button", class: "down", title: "later" }, "\u2193");
    up.addEventListener("click", () => move(problem, position, -1));
    down.addEventListener("click", () => move(problem, position, 1));
    li.append(keep, " ", el("code", {}, p.steps[index]), " ", up, down);
    return li;
  }

  function showProposals(force) {
    const box = $("proposals");
    const key = JSON.stringify([proposals, edits, running]);
    if (!force && box.dataset.key === key) { return; }
    box.dataset.key = key;
    box.replaceChildren();
    for (const [problem, p] of Object.entries(proposals)) {
      const edit = edits[problem] || (edits[problem] = { order: p.steps.map((_, i) => i), pins: {} });
      const div = el("div", { class: "proposal", "data-problem": problem, "data-generation": String(p.generation) });
      div.appendChild(el("h3", {}, problem + ": plan " + p.generation + " proposed by " + p.leader +
        " (cost " + p.cost + ", " + p.steps.length + " steps)"));
      if (p.error) { div.appendChild(el("p", { class: "note bad" }, "the change was refused: " + p.error)); }
      const list = el("ol", { class: "steps" });
      edit.order.forEach((index, position) => list.appendChild(stepRow(problem, p, position, index)));
      const dropped = p.steps.map((_, i) => i).filter((i) => !edit.order.includes(i));
      div.appendChild(list);
      if (dropped.length) {
        div.appendChild(el("p", { class: "note" }, "dropped: " + dropped.map((i) => p.steps[i]).join(", ")));
      }
      const table = el("table", { class: "tasks" });
      table.appendChild(el("tr", {}, "")).append(el("th", {}, "task"), el("th", {}, "steps"), el("th", {}, "robot"));
      for (const task of p.tasks || []) {
        const name = task.entry_point;
        const tr = el("tr", { "data-task": name });
        const pick = el("select", { "aria-label": "robot for " + name });
        pick.appendChild(el("option", { value: "" }, task.robots && task.robots.length ? task.robots.join(" or ") : "any"));
        for (const agent of meta.agents) { pick.appendChild(el("option", { value: agent }, agent)); }
        pick.value = edit.pins[name] || "";
        pick.addEventListener("change", () => {
          if (pick.value) { edit.pins[name] = pick.value; } else { delete edit.pins[name]; }
        });
        const steps = (task.steps || []).map((i) => p.steps[i]).join("; ");
        tr.append(el("td", {}, name), el("td", {}, steps), el("td", {}));
        tr.lastChild.appendChild(pick);
        table.appendChild(tr);
      }
      div.appendChild(table);
      for (const action of ["accept", "decline", "modify"]) {
        const button = el("button", { type: "button", class: action },
          { accept: "accept", decline: "decline (plan again)", modify: "run with my changes" }[action]);
        button.addEventListener("click", () => decide(problem, action));
        div.appendChild(button);
      }
      box.appendChild(div);
    }
    const shown = $("running-plan");
    shown.replaceChildren();
    for (const [problem, r] of Object.entries(running)) {
      shown.appendChild(el("p", { class: "running", "data-problem": problem }, problem + ": the team runs plan " +
        r.generation + "." + r.version + " of " + r.leader + " (cost " + r.cost + ", " + r.steps + " steps) since t = " +
        Number(r.t).toFixed(2) + " s"));
    }
  }

  // -- the connection ----------------------------------------------------------

  function receive(message) {
    const data = JSON.parse(message.data);
    if (data.type === "hello") {
      meta = data.meta;
      $("file").textContent = meta.file;
      const pick = $("problem");
      pick.replaceChildren();
      for (const [name, p] of Object.entries(meta.problems)) { pick.appendChild(el("option", { value: name }, name)); }
      const first = Object.values(meta.problems)[0];
      if (first && !$("goal").value) { $("goal").value = first.goal; }
      if (first) { checkGoal(); } else { $("goal").disabled = true; }
      if (!meta.reload) { $("reload").title = "this control center cannot load the team's plan files again"; }
    }
    data.events.forEach(take);
    count = data.count;
    state = data.state;
    for (const e of data.events) { queued.push(e); }
    for (const w of data.walls) { queuedWalls.push(w); }
    // a hidden tab gets no animation frames: keep what the next drawing needs, not the whole backlog
    if (queued.length > 2 * MAX_LOG) { queued = queued.slice(queued.length - MAX_LOG); }
    if (queuedWalls.length > 100000) { queuedWalls.splice(0, 50000); }
    if (!painting) {
      painting = true;
      setTimeout(() => requestAnimationFrame(paint), Math.max(0, lastPaint + PAINT_MS - performance.now()));
    }
  }

  // The updates that came since the last drawing are drawn together, at most every PAINT_MS: the server pushes as
  // often as events come (near 100 times a second for 10 agents under --trace-messages), and the browser's layout
  // and paint of a page that changes at every frame (the event log above all) took all of its main thread.
  function paint() {
    painting = false;
    lastPaint = performance.now();
    const fresh = queued.length > MAX_LOG ? queued.slice(queued.length - MAX_LOG) : queued;
    const walls = queuedWalls;
    queued = [];
    queuedWalls = [];
    draw();
    showLog(fresh);
    requestAnimationFrame(() => {
      const shown = Date.now();
      for (const w of walls) { window.alicaLatency.push(shown - w * 1000); }
      if (window.alicaLatency.length > 100000) { window.alicaLatency.splice(0, 50000); }
      document.body.dataset.count = String(count);
      document.body.dataset.ready = "yes";
    });
  }

  function connect() {
    const scheme = location.protocol === "https:" ? "wss://" : "ws://";
    const socket = new WebSocket(scheme + location.host + location.pathname.replace(/[^/]*$/, "") + "ws");
    socket.addEventListener("message", receive);
    socket.addEventListener("close", () => {
      $("status").textContent += " (disconnected)";
      document.body.dataset.connected = "no";
    });
    socket.addEventListener("open", () => { document.body.dataset.connected = "yes"; });
  }

  async function start() {
    const answer = await call("api/trees");
    if (answer.status === 200) { trees = answer.body; $("trees-body").dataset.plans = trees.plans || ""; }
    $("goal").addEventListener("input", checkGoal);
    $("problem").addEventListener("change", checkGoal);
    $("set-goal").addEventListener("click", setGoal);
    $("set-facts").addEventListener("click", setFacts);
    $("reload").addEventListener("click", reloadPlans);
    $("filter").addEventListener("input", refilter);
    $("raw").addEventListener("change", relog);
    connect();
  }

  start().catch((err) => { document.body.insertAdjacentHTML("afterbegin", '<p class="note bad">' + err + "</p>"); });
})();
