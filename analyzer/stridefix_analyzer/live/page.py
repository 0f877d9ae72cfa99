"""The live view's page: one HTML file with its script inline (nothing fetched from outside).

The script opens ``/ws``, merges each message into its copy of the state (new track points are
appended; a track sent from its start replaces the old one) and redraws: the floor plan (the site's
walls), the truth when the log has it, and every scheme's track on the floor shown (the primary
pose's floor unless a floor button was pressed), each in its registry colour; beside it the
primary's floor and scheme, the step count, the FIX verdicts per scheme and source, the latest fix
records, the HEALTH counters and the context. Element ids (``status``, ``floor``, ``steps``,
``primary``, ``schemes``, ``fix-table``, ``recent-fixes``, ``health-table``, ``context``, ``map``) are
what the browser test reads.
"""

PAGE = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>StrideFix live</title>
<style>
body { font-family: system-ui, -apple-system, 'Segoe UI', sans-serif; margin: 1em; color: #222; }
h1 { font-size: 1.3em; margin: 0 0 0.3em 0; } h2 { font-size: 1em; margin: 0.8em 0 0.2em 0; }
#wrap { display: flex; gap: 1.2em; align-items: flex-start; flex-wrap: wrap; }
canvas { border: 1px solid #ccc; background: #fff; }
table { border-collapse: collapse; font-size: 0.85em; } th, td { border: 1px solid #ddd; padding: 0.15em 0.5em; text-align: right; }
th { background: #f4f4f4; } td.k { text-align: left; }
.big { font-size: 1.6em; font-weight: 600; } .note { color: #666; font-size: 0.85em; }
.sw { display: inline-block; width: 0.9em; height: 0.9em; margin-right: 0.4em; vertical-align: middle; }
#floors button { margin-right: 0.3em; } #floors button.on { font-weight: 700; background: #dde8ff; }
.rej { color: #a40; } .acc { color: #260; }
</style></head>
<body>
<h1>StrideFix live</h1>
<div class="note">source <span id="source">?</span> · <span id="status">connecting</span> · walk time <span id="time">–</span></div>
<div id="wrap">
 <div><div id="floors"></div><canvas id="map" width="720" height="560"></canvas></div>
 <div>
  <div>floor <span id="floor" class="big">–</span> &nbsp; steps <span id="steps" class="big">0</span></div>
  <div class="note">primary pose: <span id="primary">–</span></div>
  <h2>Schemes</h2><table id="schemes"><tr><th class="k">scheme</th><th>floor</th><th>x [m]</th><th>y [m]</th><th>σ [m]</th><th>poses</th></tr></table>
  <h2>Fix verdicts</h2><table id="fix-table"><tr><th class="k">scheme</th><th class="k">source</th><th>offered</th><th>accepted</th><th>rejected</th><th class="k">why rejected</th></tr></table>
  <h2>Latest fixes</h2><table id="recent-fixes"><tr><th>t [s]</th><th class="k">scheme</th><th class="k">source</th><th class="k">verdict</th><th>test ratio</th><th>α</th></tr></table>
  <h2>Context</h2><div id="context" class="note">no CONTEXT message</div>
  <h2>Health</h2><table id="health-table"><tr><th class="k">counter</th><th>value</th></tr></table>
 </div>
</div>
<script>
"use strict";
const S = {schemes: {}, truth: [], walls: [], floorPick: null, doc: null};
const $ = (id) => document.getElementById(id);
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;"}[c]));
const fmt = (v, d) => (v === null || v === undefined || !isFinite(v)) ? "–" : Number(v).toFixed(d);

function merge(doc) {
  for (const s of doc.schemes) {
    const mine = S.schemes[s.code] || (S.schemes[s.code] = {track: []});
    mine.track = s.track_start === 0 ? s.track.slice() : mine.track.concat(s.track);
    Object.assign(mine, {name: s.name, colour: s.colour, last: s.last, poses: s.poses});
  }
  S.truth = doc.truth.track_start === 0 ? doc.truth.track.slice() : S.truth.concat(doc.truth.track);
  S.walls = doc.walls; S.doc = doc;
}

function floorShown() {
  const d = S.doc;
  if (S.floorPick !== null) return S.floorPick;
  if (d && d.primary) return d.primary.floor;
  return 0;
}

function floorsSeen() {
  const f = new Set();
  for (const w of S.walls) f.add(w[4]);
  for (const p of S.truth) f.add(p[2]);
  for (const s of Object.values(S.schemes)) for (const p of s.track) f.add(p[2]);
  return Array.from(f).sort((a, b) => a - b);
}

function draw() {
  const c = $("map"), g = c.getContext("2d"), fl = floorShown();
  g.clearRect(0, 0, c.width, c.height);
  let xs = [], ys = [];
  for (const w of S.walls) { xs.push(w[0], w[2]); ys.push(w[1], w[3]); }
  for (const p of S.truth) { xs.push(p[0]); ys.push(p[1]); }
  for (const s of Object.values(S.schemes)) for (const p of s.track) { xs.push(p[0]); ys.push(p[1]); }
  if (!xs.length) return;
  const x0 = Math.min(...xs) - 2, x1 = Math.max(...xs) + 2, y0 = Math.min(...ys) - 2, y1 = Math.max(...ys) + 2;
  const k = Math.min(c.width / (x1 - x0), c.height / (y1 - y0));
  const X = (x) => (x - x0) * k, Y = (y) => c.height - (y - y0) * k;
  g.strokeStyle = "#888"; g.lineWidth = 1.5;
  for (const w of S.walls) if (w[4] === fl) { g.beginPath(); g.moveTo(X(w[0]), Y(w[1])); g.lineTo(X(w[2]), Y(w[3])); g.stroke(); }
  const line = (pts, colour, width, alpha) => {
    g.strokeStyle = colour; g.lineWidth = width; g.globalAlpha = alpha; g.beginPath();
    let up = true;
    for (const p of pts) {
      if (p[2] !== fl) { up = true; continue; }
      if (up) g.moveTo(X(p[0]), Y(p[1])); else g.lineTo(X(p[0]), Y(p[1]));
      up = false;
    }
    g.stroke(); g.globalAlpha = 1;
  };
  line(S.truth, "#000", 4, 0.25);
  for (const s of Object.values(S.schemes)) {
    line(s.track, s.colour, 1.6, 0.9);
    if (s.last && s.last.floor === fl) {
      g.fillStyle = s.colour; g.beginPath(); g.arc(X(s.last.x_m), Y(s.last.y_m), 5, 0, 2 * Math.PI); g.fill();
    }
  }
}

function tables() {
  const d = S.doc;
  $("source").textContent = d.source;
  $("status").textContent = d.ended ? "log ended" : "live";
  $("time").textContent = d.t_us === null ? "–" : fmt(d.t_us / 1e6, 1) + " s";
  $("steps").textContent = d.steps;
  $("floor").textContent = d.primary ? d.primary.floor : "–";
  $("primary").textContent = d.primary ? d.primary.scheme : "–";
  const fl = floorsSeen();
  $("floors").innerHTML = fl.map((f) => `<button data-floor="${f}" class="${f === floorShown() ? "on" : ""}">floor ${f}</button>`).join("") +
    (S.floorPick !== null ? '<button data-floor="follow">follow</button>' : "");
  for (const b of $("floors").querySelectorAll("button")) b.onclick = () => {
    S.floorPick = b.dataset.floor === "follow" ? null : Number(b.dataset.floor); tables(); draw();
  };
  let rows = '<tr><th class="k">scheme</th><th>floor</th><th>x [m]</th><th>y [m]</th><th>σ [m]</th><th>poses</th></tr>';
  for (const s of Object.values(S.schemes)) {
    const l = s.last || {};
    rows += `<tr data-scheme="${esc(s.name)}"><td class="k"><span class="sw" style="background:${esc(s.colour)}"></span>${esc(s.name)}</td>` +
      `<td>${l.floor ?? "–"}</td><td>${fmt(l.x_m, 2)}</td><td>${fmt(l.y_m, 2)}</td><td>${fmt(l.sigma_m, 2)}</td><td>${s.poses}</td></tr>`;
  }
  $("schemes").innerHTML = rows;
  rows = '<tr><th class="k">scheme</th><th class="k">source</th><th>offered</th><th>accepted</th><th>rejected</th><th class="k">why rejected</th></tr>';
  for (const [scheme, methods] of Object.entries(d.fix_counts)) for (const [m, c] of Object.entries(methods)) {
    const why = Object.entries(c.rejected_by_reason).map(([r, n]) => `${esc(r)} ${n}`).join(", ");
    rows += `<tr data-scheme="${esc(scheme)}" data-method="${esc(m)}"><td class="k">${esc(scheme)}</td><td class="k">${esc(m)}</td>` +
      `<td>${c.offered}</td><td>${c.accepted}</td><td>${c.rejected}</td><td class="k">${why}</td></tr>`;
  }
  $("fix-table").innerHTML = rows;
  rows = '<tr><th>t [s]</th><th class="k">scheme</th><th class="k">source</th><th class="k">verdict</th><th>test ratio</th><th>α</th></tr>';
  for (const f of d.recent_fixes) {
    rows += `<tr><td>${fmt(f.t_us / 1e6, 1)}</td><td class="k">${esc(f.scheme)}</td><td class="k">${esc(f.method)}</td>` +
      `<td class="k ${f.accepted ? "acc" : "rej"}">${f.accepted ? "accepted" : esc(f.reason)}</td><td>${fmt(f.test_ratio, 2)}</td><td>${fmt(f.alpha, 2)}</td></tr>`;
  }
  $("recent-fixes").innerHTML = rows;
  $("context").textContent = d.context ? `context ${d.context.context} (floor ${d.context.floor}), rule ${d.context.rule_text || d.context.rule}` : "no CONTEXT message";
  rows = '<tr><th class="k">counter</th><th>value</th></tr>';
  for (const [k, v] of Object.entries(d.health)) rows += `<tr data-key="${esc(k)}"><td class="k">${esc(k)}</td><td>${esc(v)}</td></tr>`;
  $("health-table").innerHTML = rows;
}

function connect() {
  const ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
  ws.onmessage = (ev) => { merge(JSON.parse(ev.data)); tables(); draw(); document.body.dataset.version = S.doc.version; };
  ws.onclose = () => { if (!(S.doc && S.doc.ended)) { $("status").textContent = "disconnected, retrying"; setTimeout(connect, 1000); } };
}
connect();
</script>
</body></html>
"""
