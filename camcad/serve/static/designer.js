"use strict";
// camcad's live designer. Charts: uPlot (vendored before this script in /static/designer.js, MIT).
const form = document.getElementById("design-form");
const status = document.getElementById("status");
const editor = document.getElementById("motion-editor");
// The per-run token the server printed in the page's address: sent with every API call.
const TOKEN = new URLSearchParams(location.search).get("token") || "";
const INFO = JSON.parse(editor.dataset.info);  // motion keys' labels and hints, laws' parameters (the schema)
let sent = 0, drawn = 0, timer = null, waiting = false, editAt = null;
let last = null;       // the last valid answer (stays drawn while the input is invalid)
let pinned = null;     // {phi, charts} of the design pinned for compare
let liftUnit = "mm";
const NS = "http://www.w3.org/2000/svg";
const COLORS = ["#1f5f9e", "#d9731a", "#2e8b57", "#a23b72", "#6c5b7b", "#8c6d1f", "#3b8ea5", "#b03a2e"];
const BANDS = {rise: "rgba(46,139,87,0.10)", return: "rgba(217,115,26,0.10)", dwell: "rgba(120,120,120,0.06)",
               table: "rgba(31,95,158,0.06)"};
const EDGES = {rise: "#2e8b57", return: "#d9731a", dwell: "#9a9a9a", table: "#1f5f9e"};

function settle() {  // "1" while a change is not yet drawn (tests and screen readers wait on it)
  document.body.dataset.busy = waiting || drawn !== sent ? "1" : "0";
}

// ------------------------------------------------------------------ the motion program (the model)
const SEG_KEYS = ["kind", "angle", "lift", "law", "velocity", "file", "noise"];
function fromTable(t, i) {
  const s = {source: i};
  for (const [k, v] of Object.entries(t)) if (typeof v !== "object") s[k] = String(v);
  return s;
}
let segments = JSON.parse(editor.dataset.motion).map(fromTable);

function lawParams(law) { return ((INFO.laws[law] || {}).parameters || []); }
function segKeys(s) {
  if (s.kind === "table") return ["kind", "file", "noise"];
  if (s.kind === "dwell") return ["kind", "angle"];
  const keys = ["kind", "angle", "velocity" in s ? "velocity" : "lift", "law"];
  return keys.concat(lawParams(s.law).map(p => p.name));
}
function spans() {  // [start, end] of each segment in degrees, from the angles typed
  let at = 0;
  return segments.map(s => {
    const a = s.kind === "table" ? 360 : parseFloat(s.angle);
    const span = [at, at + (isFinite(a) ? a : 0)]; at = span[1]; return span;
  });
}
function fmtDeg(x) { return (+x.toFixed(3)) + "°"; }

function control(s, i, key) {
  const id = `f-motion-${i}-${key}`, path = `motion[${i}].${key}`;
  const wrap = document.createElement("div"); wrap.className = "field";
  const label = document.createElement("label"); label.htmlFor = id; label.title = path;
  const param = lawParams(s.law).find(p => p.name === key);
  const info = INFO.keys[key] || {};
  let unit = info.unit || "";
  if (key === "lift" || key === "velocity") unit = key === "lift" ? liftUnit : liftUnit + "/s";
  label.textContent = (param ? param.label : info.label || key);
  if (unit) { const u = document.createElement("span"); u.className = "unit"; u.textContent = ` [${unit}]`; label.append(u); }
  let input;
  const choices = key === "kind" ? INFO.kinds : key === "law" ? Object.keys(INFO.laws) : null;
  if (choices) {  // required: no "(default)"
    input = document.createElement("select");
    for (const c of choices) { const o = document.createElement("option"); o.value = o.textContent = c; input.append(o); }
    input.value = s[key] || "";
  } else {
    input = document.createElement("input"); input.type = "text"; input.value = s[key] || "";
    input.autocomplete = "off"; input.spellcheck = false;
    if (key !== "file") input.inputMode = "decimal";
  }
  input.id = id; input.name = path; input.dataset.seg = i; input.dataset.key = key;
  const described = [];
  const hintText = param ? param.allowed : (key === "law" ? (INFO.laws[s.law] || {}).summary : info.hint) || "";
  wrap.append(label, input);
  if (hintText && !(choices && key === "kind")) {
    const hint = document.createElement("span"); hint.className = "hint"; hint.id = id + "-hint"; hint.textContent = hintText;
    wrap.append(hint); described.push(hint.id);
  }
  const err = document.createElement("span"); err.className = "err"; err.id = id + "-err"; err.dataset.for = path;
  err.setAttribute("role", "alert"); wrap.append(err); described.push(err.id);
  input.setAttribute("aria-describedby", described.join(" "));
  return wrap;
}

function button(text, label, action, disabled) {
  const b = document.createElement("button"); b.type = "button"; b.textContent = text;
  b.setAttribute("aria-label", label); b.disabled = !!disabled;
  b.addEventListener("click", action); return b;
}

function renderSegments(focusId) {
  const at = spans();
  const boxes = segments.map((s, i) => {
    const box = document.createElement("div"); box.className = "segment"; box.id = "segment-" + i;
    box.setAttribute("role", "group"); box.setAttribute("aria-labelledby", `segment-${i}-title`);
    box.style.setProperty("--seg", EDGES[s.kind] || "#9bb3cc");
    const head = document.createElement("h4");
    const title = document.createElement("span"); title.id = `segment-${i}-title`;
    title.textContent = `Segment ${i + 1}: ${fmtDeg(at[i][0])} to ${fmtDeg(at[i][1])}`;
    const n = i + 1, last = segments.length - 1;
    head.append(title,
      button("↑", `Move segment ${n} earlier`, () => edit(() => swap(i, i - 1), `seg-${i - 1}-up`), i === 0),
      button("↓", `Move segment ${n} later`, () => edit(() => swap(i, i + 1), `seg-${i + 1}-down`), i === last),
      button("Split", `Split segment ${n} in two`, () => edit(() => split(i)), s.kind === "table"),
      button("Delete", `Delete segment ${n}`, () => edit(() => remove(i)), segments.length < 2));
    head.querySelectorAll("button").forEach((b, k) => { b.id = `seg-${i}-${["up", "down", "split", "delete"][k]}`; });
    box.append(head);
    for (const key of segKeys(s)) box.append(control(s, i, key));
    return box;
  });
  editor.replaceChildren(...boxes);
  if (focusId) { const f = document.getElementById(focusId); if (f && !f.disabled) f.focus(); }
}

function swap(i, j) { [segments[i], segments[j]] = [segments[j], segments[i]]; }
function half(x) { const v = parseFloat(x); return isFinite(v) ? String(+(v / 2).toFixed(6)) : x; }
function split(i) {
  const s = segments[i], a = {...s, angle: half(s.angle)}, b = {...s, angle: half(s.angle)};
  delete b.source;
  if (s.lift !== undefined && s.lift !== "close") { a.lift = half(s.lift); b.lift = half(s.lift); }
  if (s.lift === "close") { a.lift = "close"; b.lift = "close"; }
  segments.splice(i, 1, a, b);
}
function remove(i) {
  const gone = segments.splice(i, 1)[0];
  const into = segments[Math.max(0, i - 1)];
  const a = parseFloat(into.angle), g = parseFloat(gone.angle);
  if (into.kind !== "table" && isFinite(a) && isFinite(g)) into.angle = String(+(a + g).toFixed(6));
}
function addSegment() {  // a dwell cut from the end of the last segment
  const s = segments[segments.length - 1];
  if (s.kind === "table") { segments = [{kind: "dwell", angle: "360"}]; return; }
  const a = parseFloat(s.angle);
  const cut = isFinite(a) ? +(Math.min(30, a / 2)).toFixed(6) : 30;
  if (isFinite(a)) s.angle = String(+(a - cut).toFixed(6));
  segments.push({kind: "dwell", angle: String(cut)});
}

function changeKind(s, kind) {
  s.kind = kind;
  if (kind === "dwell") { for (const k of Object.keys(s)) if (!["kind", "angle", "source"].includes(k)) delete s[k]; }
  else if (kind === "table") {
    for (const k of Object.keys(s)) if (!["kind", "file", "noise", "source"].includes(k)) delete s[k];
    s.law = "table";
  } else {
    if (!s.law || s.law === "table") s.law = "cycloidal";
    if (s.lift === undefined && s.velocity === undefined) s.lift = kind === "return" ? "close" : "10";
    if (!s.angle) s.angle = "90";
    delete s.file; delete s.noise;
  }
}
function changeLaw(s, law) {
  for (const p of lawParams(s.law)) delete s[p.name];
  if (law !== "constant-velocity" && s.velocity !== undefined) { s.lift = "close"; delete s.velocity; }
  s.law = law;
}

editor.addEventListener("input", ev => {
  const t = ev.target; if (!t.dataset.key) return;
  segments[+t.dataset.seg][t.dataset.key] = t.value;
  if (t.dataset.key === "angle") relabel();
});
editor.addEventListener("change", ev => {
  const t = ev.target; if (!t.dataset.key) return;
  const s = segments[+t.dataset.seg];
  if (t.dataset.key === "kind") { changeKind(s, t.value); renderSegments(t.id); }
  else if (t.dataset.key === "law") { changeLaw(s, t.value); renderSegments(t.id); }
  else s[t.dataset.key] = t.value;
  record(); drawBands();
});
function relabel() {
  const at = spans();
  segments.forEach((s, i) => {
    const t = document.getElementById(`segment-${i}-title`);
    if (t) t.textContent = `Segment ${i + 1}: ${fmtDeg(at[i][0])} to ${fmtDeg(at[i][1])}`;
  });
  drawBands();
}

function edit(change, focusId) {  // a change of the program's structure: redraw the editor, analyse, record
  change(); renderSegments(focusId); record(); drawBands(); edited(); later(0);
}
document.getElementById("seg-add").addEventListener("click", () => edit(addSegment));

// ------------------------------------------------------------------ the values sent, undo and redo
function values() {
  const out = {};
  for (const el of form.querySelectorAll("input[name], select[name]")) out[el.name] = el.value;
  out["motion.count"] = String(segments.length);
  segments.forEach((s, i) => {
    for (const key of segKeys(s)) if (!(`motion[${i}].${key}` in out)) out[`motion[${i}].${key}`] = s[key] || "";
    if (s.kind === "table") out[`motion[${i}].law`] = "table";
    if (s.source !== undefined) out[`motion[${i}].source`] = String(s.source);
  });
  return out;
}
function snapshot() {
  const fields = {};
  for (const el of form.querySelectorAll("input[name], select[name]")) if (!el.dataset.key) fields[el.name] = el.value;
  return JSON.stringify({fields, segments});
}
let history = [], at = -1;
function record() {
  const now = snapshot();
  if (history[at] === now) return;
  history = history.slice(0, at + 1); history.push(now); at = history.length - 1;
  if (history.length > 200) { history.shift(); at--; }
  undoState();
}
function restore(text) {
  const snap = JSON.parse(text);
  for (const [name, v] of Object.entries(snap.fields)) {
    const el = form.querySelector(`[name="${CSS.escape(name)}"]`); if (el) el.value = v;
  }
  segments = snap.segments; renderSegments(); drawBands(); edited(); later(0);
}
function undoState() {
  document.getElementById("undo").disabled = at <= 0;
  document.getElementById("redo").disabled = at >= history.length - 1;
}
document.getElementById("undo").addEventListener("click", () => { if (at > 0) { at--; restore(history[at]); undoState(); } });
document.getElementById("redo").addEventListener("click", () => { if (at < history.length - 1) { at++; restore(history[at]); undoState(); } });
document.addEventListener("keydown", ev => {
  if (!(ev.ctrlKey || ev.metaKey) || ev.altKey) return;
  const k = ev.key.toLowerCase();
  if (k === "z" && !ev.shiftKey) { ev.preventDefault(); document.getElementById("undo").click(); }
  if (k === "y" || (k === "z" && ev.shiftKey)) { ev.preventDefault(); document.getElementById("redo").click(); }
});

// ------------------------------------------------------------------ the charts (uPlot)
const plots = {};  // key → {u, box, chart}
function interp(xs, ys, x) {  // ys at x on the grid xs: exact at its own samples, linear between
  let lo = 0, hi = xs.length - 1;
  if (!(x >= xs[lo] && x <= xs[hi])) return null;
  while (hi - lo > 1) { const m = (lo + hi) >> 1; if (xs[m] <= x) lo = m; else hi = m; }
  if (x === xs[lo]) return ys[lo];
  if (x === xs[hi]) return ys[hi];
  const a = ys[lo], b = ys[hi];
  if (a === null || b === null) return null;
  return a + (x - xs[lo]) / (xs[hi] - xs[lo]) * (b - a);
}
function union(a, b) {  // two sorted angle lists merged, each angle once
  const out = []; let i = 0, k = 0;
  while (i < a.length || k < b.length) {
    const x = k >= b.length || (i < a.length && a[i] <= b[k]) ? a[i] : b[k];
    if (i < a.length && a[i] === x) i++;
    if (k < b.length && b[k] === x) k++;
    out.push(x);
  }
  return out;
}
const MOTION = ["s", "v", "a", "j"];
function bandsHook(u) {
  const ctx = u.ctx, {top, height} = u.bbox, at = spans();
  ctx.save();
  segments.forEach((s, i) => {
    const x0 = u.valToPos(at[i][0], "x", true), x1 = u.valToPos(at[i][1], "x", true);
    ctx.fillStyle = BANDS[s.kind] || BANDS.dwell; ctx.fillRect(x0, top, x1 - x0, height);
    ctx.strokeStyle = EDGES[s.kind] || "#999"; ctx.lineWidth = 1.5 * devicePixelRatio;
    ctx.beginPath(); ctx.moveTo(x1, top); ctx.lineTo(x1, top + height); ctx.stroke();
    ctx.fillStyle = "#555"; ctx.font = `${10 * devicePixelRatio}px sans-serif`;
    if (x1 - x0 > 30 * devicePixelRatio) ctx.fillText(`${i + 1} ${s.kind}`, x0 + 3 * devicePixelRatio, top + 11 * devicePixelRatio);
  });
  ctx.restore();
}
function overlayHook(u) {  // limit lines and a point table's own points
  const p = plots[u.root.dataset.key]; if (!p) return;
  const ctx = u.ctx, {left, top, width, height} = u.bbox;
  ctx.save(); ctx.beginPath(); ctx.rect(left, top, width, height); ctx.clip();
  ctx.strokeStyle = "#c0392b"; ctx.setLineDash([5 * devicePixelRatio, 3 * devicePixelRatio]); ctx.lineWidth = devicePixelRatio;
  for (const y of p.chart.limits || []) {
    const py = u.valToPos(y, "y", true);
    ctx.beginPath(); ctx.moveTo(left, py); ctx.lineTo(left + width, py); ctx.stroke();
  }
  ctx.setLineDash([]);
  const pts = p.chart.points;
  if (pts) {
    ctx.fillStyle = "rgba(192,57,43,0.75)";
    for (let k = 0; k < pts.phi_deg.length; k++) {
      const x = u.valToPos(pts.phi_deg[k], "x", true), y = u.valToPos(pts.s[k], "y", true);
      ctx.beginPath(); ctx.arc(x, y, 1.8 * devicePixelRatio, 0, 2 * Math.PI); ctx.fill();
    }
  }
  ctx.restore();
}
function chartWidth(box) { return Math.max(200, Math.floor(box.clientWidth || 320)); }

function plotData(chart) {  // each chart comes on its own (min-max decimated) angles
  const old = pinned ? pinned.charts.find(c => c.key === chart.key) : null;
  const phi = old ? union(chart.phi_deg, old.phi_deg) : chart.phi_deg;  // both curves keep every sample
  const data = [phi], series = [{label: "φ [°]", value: (u, v) => v == null ? "–" : v.toFixed(1)}];
  chart.series.forEach((s, k) => {
    data.push(old ? phi.map(x => interp(chart.phi_deg, s.y, x)) : s.y);
    series.push({label: s.label + (chart.unit ? ` [${chart.unit}]` : ""), stroke: COLORS[k % COLORS.length], width: 1.4,
                 value: (u, v) => v == null ? "–" : +v.toPrecision(5)});
  });
  if (old) {
    old.series.forEach((s, k) => {
      data.push(phi.map(x => interp(old.phi_deg, s.y, x)));
      series.push({label: "pinned " + s.label, stroke: "#7d7d7d", width: 1.2, dash: [6, 4],
                   value: (u, v) => v == null ? "–" : +v.toPrecision(5)});
    });
  }
  if (chart.points) series[1].label += " (smoothing spline; dots: the table's points)";
  return {data, series};
}

function drawChart(parent, chart, motion) {
  let p = plots[chart.key];
  const {data, series} = plotData(chart);
  const sig = series.map(s => s.label).join("|");
  if (!p) {
    const fig = document.createElement("figure"); fig.className = "chart";
    const h = document.createElement("h3"); h.id = "chart-title-" + chart.key;
    h.textContent = chart.title + (chart.unit ? " [" + chart.unit + "]" : "") + " ";
    const tag = document.createElement("span"); tag.className = "stale-tag"; tag.textContent = "out of date"; h.append(tag);
    const box = document.createElement("div"); box.className = "plot"; box.id = "chart-" + chart.key;
    box.setAttribute("role", "img");
    box.setAttribute("aria-label", chart.title + (motion ? " against the cam angle, with the motion segments as bands" : " against the cam angle"));
    fig.append(h, box); parent.append(fig);
    p = plots[chart.key] = {box, chart, u: null, sig: ""};
  }
  p.chart = chart;
  let lo = Infinity, hi = -Infinity;
  for (const s of chart.series) for (const y of s.y) if (y !== null) { lo = Math.min(lo, y); hi = Math.max(hi, y); }
  p.box.dataset.ymin = lo; p.box.dataset.ymax = hi; p.box.dataset.series = chart.series.length;
  p.box.dataset.pinned = pinned && pinned.charts.some(c => c.key === chart.key) ? "1" : "0";
  if (p.u && p.sig === sig) {
    const x = p.u.scales.x, zoomed = p.zoomed ? [x.min, x.max] : null;
    p.u.setData(data);
    if (zoomed) p.u.setScale("x", {min: zoomed[0], max: zoomed[1]});
    return;
  }
  if (p.u) p.u.destroy();
  const opts = {
    width: chartWidth(p.box), height: 200, series,
    scales: {x: {time: false, range: (u, a, b) => [a ?? 0, b ?? 360]},
             y: {range: (u, a, b) => {
               if (p.frozenY) return p.frozenY;  // a blend point is being dragged: the scale holds still
               for (const l of p.chart.limits || []) { a = Math.min(a, l); b = Math.max(b, l); }
               const pad = (b - a) * 0.06 || 1; return [a - pad, b + pad]; }}},
    axes: [{values: (u, v) => v.map(x => x + "°")}, {size: 56}],
    cursor: {drag: {x: true, y: false}},
    legend: {live: true},
    hooks: {drawClear: motion ? [bandsHook] : [], draw: motion ? [overlayHook, blendHook] : [overlayHook],
            setScale: [(u, key) => { if (key === "x") p.zoomed = !(u.scales.x.min <= 0.01 && u.scales.x.max >= 359.99); }]},
  };
  p.u = new uPlot(opts, data, p.box);
  p.u.root.dataset.key = chart.key;
  p.sig = sig;
  if (motion) dragBoundaries(p);
}
function drawBands() { for (const k of MOTION) if (plots[k] && plots[k].u) plots[k].u.redraw(false, false); }
window.addEventListener("resize", () => { for (const p of Object.values(plots)) if (p.u) p.u.setSize({width: chartWidth(p.box), height: 200}); });

// Blend points: the ends of the segments on the displacement chart, at (angle, lift). Dragging one moves
// the boundary (as the line does) and, up or down, the lift there: the last rise or return up to it (the
// segment itself, or the one before the dwells ending there) rises or falls by as much more, and the next
// rise or return after it by as much less, so the rest of the program stays where it was ("close" closes
// by itself). The values go through the editor's fields and the same analysis as typing them; a value the
// loader refuses shows its message under the field.
let blend = null;  // {k, x, y} while a blend point is dragged (drawn at the cursor until the answer comes)
function liftSign(s) { return s.kind === "rise" ? 1 : s.kind === "return" ? -1 : 0; }
function numeric(x) { return x !== undefined && x !== "" && x !== "close" && isFinite(parseFloat(x)); }
function lifter(k) {  // the segment whose lift sets the height at the end of segment k (-1: none can)
  let i = k;
  while (i >= 0 && segments[i].kind === "dwell") i--;
  const s = segments[i];
  return i >= 0 && liftSign(s) !== 0 && s.velocity === undefined && numeric(s.lift) ? i : -1;
}
function movable(k) { return lifter(k) >= 0; }
function blendPoints() {  // [{k, x [°], y}] of every boundary between two segments, y on the drawn curve
  const p = plots.s; if (!p || !p.chart) return [];
  const at = spans(), xs = p.chart.phi_deg, ys = p.chart.series[0].y;
  const out = [];
  for (let k = 0; k < segments.length - 1; k++) {
    const y = interp(xs, ys, at[k][1]);
    if (y !== null) out.push({k, x: at[k][1], y});
  }
  return out;
}
window.camcadBlendPoints = blendPoints;
function blendHook(u) {  // the blend points as handles on the displacement chart
  if (u.root.dataset.key !== "s") return;
  const ctx = u.ctx, r = devicePixelRatio;
  ctx.save();
  for (const b of blendPoints()) {
    const at = blend && blend.k === b.k ? blend : b;
    const x = u.valToPos(at.x, "x", true), y = u.valToPos(at.y, "y", true);
    ctx.beginPath(); ctx.arc(x, y, 5 * r, 0, 2 * Math.PI);
    ctx.fillStyle = movable(b.k) ? "#fff" : "#eee"; ctx.fill();
    ctx.lineWidth = 2 * r; ctx.strokeStyle = "#1f3b57"; ctx.stroke();
  }
  ctx.restore();
}
function blendTo(k, x, lift0, y0, y) {  // the blend point after segment k to angle x [°] and height y
  const d = y - y0, i = lifter(k);
  if (i >= 0) {
    const s = segments[i];
    s.lift = String(+(parseFloat(lift0[i]) + liftSign(s) * d).toFixed(3));
    const j = segments.findIndex((t, n) => n > k && liftSign(t) !== 0);
    if (j > k && numeric(lift0[j]) && segments[j].velocity === undefined) {
      segments[j].lift = String(+(parseFloat(lift0[j]) - liftSign(segments[j]) * d).toFixed(3));
    }
    segments.forEach((t, n) => {
      const f = document.getElementById(`f-motion-${n}-lift`); if (f && t.lift !== undefined) f.value = t.lift;
    });
  }
  dragTo(k, x);
}

function dragBoundaries(p) {  // drag the line between two segments: both spans change, their sum stays
  const over = p.u.over;
  let drag = null;
  const near = ev => {
    const r = over.getBoundingClientRect(), x = ev.clientX - r.left, at = spans();
    for (let k = 0; k < segments.length - 1; k++) if (Math.abs(p.u.valToPos(at[k][1], "x") - x) < 7) return k;
    return -1;
  };
  const nearPoint = ev => {  // a blend point within 8 px (displacement chart only)
    if (p.chart.key !== "s") return null;
    const r = over.getBoundingClientRect(), x = ev.clientX - r.left, y = ev.clientY - r.top;
    return blendPoints().find(b => Math.hypot(p.u.valToPos(b.x, "x") - x, p.u.valToPos(b.y, "y") - y) < 8) || null;
  };
  over.addEventListener("mousemove", ev => {
    if (drag) return;
    const b = nearPoint(ev);
    over.style.cursor = b ? (movable(b.k) ? "move" : "ew-resize") : near(ev) >= 0 ? "ew-resize" : "";
  });
  over.addEventListener("mousedown", ev => {
    const b = nearPoint(ev), k = b ? b.k : near(ev); if (k < 0) return;
    ev.stopPropagation(); ev.preventDefault();
    const at = spans();
    // the chart's place when the drag began: a banner or status line changing above it while the mouse is
    // held moves the chart, not the values the hand's movement means
    drag = {k, lo: at[k][0], hi: at[k + 1][1], point: b, lift0: segments.map(s => s.lift),
            rect: over.getBoundingClientRect()};
    if (b) p.frozenY = [p.u.scales.y.min, p.u.scales.y.max];  // answers during the drag do not rescale
  }, true);
  window.addEventListener("mousemove", ev => {
    if (!drag) return;
    const r = drag.rect;
    let x = Math.round(p.u.posToVal(ev.clientX - r.left, "x") * 2) / 2;
    x = Math.min(drag.hi - 0.5, Math.max(drag.lo + 0.5, x));
    if (!drag.point) { dragTo(drag.k, x); return; }
    const y = movable(drag.k) ? Math.round(p.u.posToVal(ev.clientY - r.top, "y") * 100) / 100 : drag.point.y;
    blend = {k: drag.k, x, y};
    blendTo(drag.k, x, drag.lift0, drag.point.y, y);
  });
  window.addEventListener("mouseup", () => {
    if (!drag) return;
    drag = null; blend = null; record();
    if (p.frozenY) { p.frozenY = null; p.u.setData(p.u.data, true); }  // the scale fits the curve again
    drawBands();
  });
}
function dragTo(k, x) {  // the boundary after segment k to the angle x [°] (also used by tests and keyboard)
  const at = spans(), lo = at[k][0], hi = at[k + 1][1];
  segments[k].angle = String(+(x - lo).toFixed(6));
  segments[k + 1].angle = String(+(hi - x).toFixed(6));
  for (const j of [k, k + 1]) { const f = document.getElementById(`f-motion-${j}-angle`); if (f) f.value = segments[j].angle; }
  relabel(); edited(); later(40);
}
window.camcadDragBoundary = dragTo;

// ------------------------------------------------------------------ the cam drawing (SVG, to scale)
function el(tag, attrs, parent) {
  const node = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
  if (parent) parent.appendChild(node);
  return node;
}
function pathOf(points, close) {
  if (!points.length) return "";
  return "M" + points.map(p => p[0] + " " + p[1]).join("L") + (close ? "Z" : "");
}
function drawFollowers(g, svg, followers, w, offset) {
  followers.forEach((f, k) => {
    const c = COLORS[(k + 1 + offset) % COLORS.length];
    for (const p of f.body) el("path", {d: pathOf(p, false), fill: "none", stroke: c, "stroke-width": 2 * w}, g);
    for (const p of f.links) el("path", {d: pathOf(p, false), fill: "none", stroke: c, "stroke-width": 2.6 * w}, g);
    for (const p of f.axes) el("path", {d: pathOf(p, false), fill: "none", stroke: c, "stroke-width": 0.8 * w, "stroke-dasharray": `${8 * w} ${3 * w}`}, g);
    if (!offset) {
      const t = el("text", {x: f.label_at[0], y: -f.label_at[1], "font-size": 11 * w * 1.6, fill: c, "text-anchor": "middle"}, svg);
      t.textContent = "φ = " + f.phi_deg + "°";
    }
  });
}
function drawCam(box, d) {
  let reach = d.profile_radius_max;
  if (d.groove) reach = Math.max(reach, d.groove.outer_radius);
  const all = [...d.followers, ...(d.second ? d.second.followers : [])];
  for (const f of all) for (const part of [...f.body, ...f.links]) for (const p of part) reach = Math.max(reach, Math.hypot(p[0], p[1]));
  const lim = 1.15 * reach;
  const svg = el("svg", {viewBox: `${-lim} ${-lim} ${2 * lim} ${2 * lim}`, role: "img", "aria-label": "cam drawing"});
  svg.dataset.profileRadiusMax = d.profile_radius_max;
  svg.dataset.baseRadius = d.base_radius;
  const g = el("g", {transform: "scale(1,-1)"}, svg);
  const w = lim / 250;
  if (d.groove) {
    el("circle", {id: "groove-blank", cx: 0, cy: 0, r: d.groove.outer_radius, fill: "#dbe6f1", stroke: "#1f3b57", "stroke-width": 1.5 * w}, g);
    el("path", {id: "groove-outer", d: pathOf(d.groove.outer, true), fill: "#fff", stroke: "#1f3b57", "stroke-width": 2 * w}, g);
    el("path", {id: "groove-inner", d: pathOf(d.groove.inner, true), fill: "#dbe6f1", stroke: "#1f3b57", "stroke-width": 2 * w}, g);
  } else {
    el("path", {id: "cam-profile", d: pathOf(d.profile, true), fill: "#dbe6f1", stroke: "#1f3b57", "stroke-width": 2 * w}, g);
  }
  if (d.second) el("path", {id: "second-plate", d: pathOf(d.second.profile, true), fill: "none", stroke: "#b5651d", "stroke-width": 2 * w}, g);
  if (d.bore.length) el("path", {d: pathOf(d.bore, true), fill: "#fff", stroke: "#1f3b57", "stroke-width": 1.5 * w}, g);
  el("path", {d: pathOf(d.trace, true), fill: "none", stroke: "#d9731a", "stroke-dasharray": `${6 * w} ${4 * w}`, "stroke-width": 1.3 * w}, g);
  el("circle", {cx: 0, cy: 0, r: d.base_radius, fill: "none", stroke: "#7f7f7f", "stroke-dasharray": `${2 * w} ${3 * w}`, "stroke-width": w}, g);
  drawFollowers(g, svg, d.followers, w, 0);
  if (d.second) drawFollowers(g, svg, d.second.followers, w, 4);
  box.replaceChildren(svg);
}

// ------------------------------------------------------------------ errors, state, the answer drawn
function showErrors(errors) {
  for (const span of form.querySelectorAll(".err")) span.textContent = "";
  for (const input of form.querySelectorAll("[aria-invalid]")) input.removeAttribute("aria-invalid");
  const general = document.getElementById("general-error");
  general.textContent = "";
  for (const e of errors) {
    const span = [...form.querySelectorAll(".err")].find(s => s.dataset.for === e.field);
    if (span && span.id !== "table-err") {
      span.textContent = e.message;
      const input = document.getElementById(span.id.slice(0, -4));
      input.setAttribute("aria-invalid", "true");
      const box = input.closest("details"); if (box) box.open = true;
    } else {
      general.textContent = (e.field ? e.field + ": " : "") + e.message;
    }
  }
}
// The speed range that keeps a spring-held follower on the cam: summary.json's [low, high] rpm, where an
// unbounded end is null (infinite in camcad: no speed up to it lifts the follower off the cam).
function rpm(v) { return (+v.toPrecision(4)) + " rpm"; }
function speedRange(range) {
  if (range === null) return "none: the follower leaves the cam at every speed";
  const [lo, hi] = range;
  const low = lo === null || !isFinite(lo) ? "no lower limit" : rpm(lo);
  const high = hi === null || !isFinite(hi) ? "no upper limit" : rpm(hi);
  return low + " to " + high;
}
function showSpeedRange(out) {
  const box = document.getElementById("speed-range"), dyn = (out.summary || {}).dynamics || {};
  if (!("speed_range_rpm" in dyn)) { box.replaceChildren(); return; }  // a positive drive: no such range
  const words = document.createElement("span"); words.textContent = "Speed range without leaving the cam: ";
  const value = document.createElement("strong"); value.id = "speed-range-value";
  value.textContent = speedRange(dyn.speed_range_rpm);
  const tag = document.createElement("span"); tag.className = "stale-tag"; tag.textContent = " out of date";
  box.replaceChildren(words, value, tag);
}
const STALE = '<section class="alert bad" id="stale"><h2>Out of date</h2><p>The input is invalid (see the ' +
  'field marked): the drawing, numbers and curves below are those of the last valid design.</p></section>';
function render(out) {
  showErrors(out.errors);
  const alerts = document.getElementById("alerts");
  if (out.ok) {
    last = out;
    if (out.lift_unit && out.lift_unit !== liftUnit) {
      liftUnit = out.lift_unit;
      const f = document.activeElement;
      renderSegments(f && editor.contains(f) ? f.id : null);
    }
    alerts.innerHTML = out.alerts;
    const cards = document.getElementById("cards");
    cards.innerHTML = out.cards;
    for (const card of cards.querySelectorAll(".card .label")) {
      const tag = document.createElement("span"); tag.className = "stale-tag"; tag.textContent = " out of date"; card.append(tag);
    }
    showSpeedRange(out);
    drawCam(document.getElementById("cam-drawing-svg"), out.drawing);
    document.getElementById("cam-caption").textContent = out.drawing.caption;
    for (const chart of out.charts) {
      const motion = MOTION.includes(chart.key);
      drawChart(document.getElementById(motion ? "motion-diagram" : "charts"), chart, motion);
    }
  } else {
    alerts.innerHTML = STALE;  // no "No warnings" while invalid: the old banner said nothing about this input
  }
  compareTable(last);
  document.body.dataset.state = out.ok ? "ok" : "invalid";
  document.body.dataset.everValid = last ? "1" : "0";
}

async function post(url, body) {
  return fetch(url, {
    method: "POST", credentials: "omit", cache: "no-store",
    headers: {"Content-Type": "application/json", "X-Camcad-Token": TOKEN},
    body: JSON.stringify(body),
  });
}
async function answer(response) {  // the JSON of any answer, or an error in the same shape
  try { return await response.json(); }
  catch (err) { return {ok: false, errors: [{field: "", message: "the server sent no answer (" + response.status + ")"}]}; }
}
function unreachable() {
  return {ok: false, errors: [{field: "", message: "the designer server is not reachable (was camcad serve stopped?)"}]};
}

let notes = 0;  // counts save and build messages: an analysis that began before one does not overwrite it

let inflight = false, again = false;  // one analysis at a time per page; edits meanwhile coalesce into one

async function analyse(notesFrom) {  // notesFrom: the notes count when the change now sent was first sent
  if (inflight) { again = true; waiting = true; settle(); return; }
  inflight = true;
  waiting = false;
  const id = ++sent;
  const notesBefore = typeof notesFrom === "number" ? notesFrom : notes, since = editAt;
  editAt = null;
  settle();
  if (notes === notesBefore) status.textContent = "analysing…";  // a save or build said since stays said
  const started = performance.now();
  let out;
  try { out = await answer(await post("/api/analyse", {values: values()})); } catch (err) { out = unreachable(); }
  inflight = false;
  if (again) {  // a newer change came meanwhile: send it (its latency counted from the first change undrawn)
    again = false; if (since !== null) editAt = since; analyse(notesBefore); return;
  }
  if (id !== sent) return;
  const answered = performance.now();
  render(out);
  await new Promise(r => requestAnimationFrame(() => r()));
  document.body.dataset.fetchMs = String(Math.round(answered - started));  // request, analysis, answer
  document.body.dataset.drawMs = String(Math.round(performance.now() - answered));  // the page redrawn
  drawn = id;
  document.body.dataset.revision = String(id);
  if (since !== null) document.body.dataset.latency = String(Math.round(performance.now() - since));
  settle();
  if (notes === notesBefore) {
    status.textContent = (out.ok ? "updated" : "invalid input") + " in " + Math.round(performance.now() - started) + " ms";
  }
}

function edited() { if (editAt === null) editAt = performance.now(); }
function later(ms) { clearTimeout(timer); waiting = true; settle(); timer = setTimeout(analyse, ms); }
form.addEventListener("input", ev => { if (ev.target.type !== "file") { edited(); later(150); } });
form.addEventListener("change", ev => {
  if (ev.target.type === "file") return;
  edited(); later(0); if (!ev.target.dataset.key) record();
});
form.addEventListener("submit", ev => ev.preventDefault());

// ------------------------------------------------------------------ compare: pin the current design
function unitWords(key) {  // "pressure_angle_max_deg" → ["pressure angle max", "°"] (summary.json's own keys)
  const units = {deg: "°", mm: "mm", N: "N", Nmm: "N·mm", MPa: "MPa", mm_per_rad: "mm/rad",
                 mm_per_rad2: "mm/rad²", mm_per_rad3: "mm/rad³", deg_per_rad: "°/rad", deg_per_rad2: "°/rad²",
                 deg_per_rad3: "°/rad³"};
  for (const [tail, u] of Object.entries(units).sort((a, b) => b[0].length - a[0].length)) {
    if (key.endsWith("_" + tail)) return [key.slice(0, -tail.length - 1).replace(/_/g, " "), u];
  }
  return [key.replace(/_/g, " "), ""];
}
function compareTable(now) {
  const box = document.getElementById("compare");
  if (!pinned || !now) { box.replaceChildren(); return; }
  const table = document.createElement("table"); table.id = "compare-table";
  const cap = document.createElement("caption"); cap.textContent = "Pinned design against this one";
  const head = table.createTHead().insertRow();
  for (const t of ["quantity", "pinned", "now", "change"]) { const th = document.createElement("th"); th.scope = "col"; th.textContent = t; head.append(th); }
  table.prepend(cap);
  const body = table.createTBody();
  for (const part of ["motion", "geometry", "dynamics"]) {
    const a = pinned.summary[part] || {}, b = now.summary[part] || {};
    for (const key of Object.keys(b)) {
      if (typeof b[key] !== "number" || typeof a[key] !== "number" || key.endsWith("_angle_deg")) continue;
      const [words, unit] = unitWords(key), row = body.insertRow(); row.dataset.key = part + "." + key;
      const f = v => (+v.toPrecision(6)) + (unit ? " " + unit : "");
      const d = b[key] - a[key];
      for (const t of [words, f(a[key]), f(b[key]), (d > 0 ? "+" : "") + (+d.toPrecision(4))]) row.insertCell().textContent = t;
    }
  }
  const a = (pinned.summary.dynamics || {}), b = (now.summary.dynamics || {});
  if ("speed_range_rpm" in a && "speed_range_rpm" in b) {
    const row = body.insertRow(); row.dataset.key = "dynamics.speed_range_rpm";
    for (const t of ["speed range without leaving", speedRange(a.speed_range_rpm), speedRange(b.speed_range_rpm), ""]) row.insertCell().textContent = t;
  }
  box.replaceChildren(table);
}
const pinButton = document.getElementById("pin");
pinButton.addEventListener("click", () => {
  if (pinned) { pinned = null; }
  else if (last) { pinned = {charts: last.charts, summary: last.summary}; }
  pinButton.setAttribute("aria-pressed", pinned ? "true" : "false");
  pinButton.textContent = pinned ? "Unpin" : "Pin for compare";
  document.getElementById("pin-note").textContent = pinned ? "pinned curves: grey dashed" : "";
  if (last) render(last);
});

// ------------------------------------------------------------------ point table upload (explicit save)
const tableFile = document.getElementById("table-file"), tableSave = document.getElementById("table-save");
const tableErr = document.getElementById("table-err");
let upload = null;
tableFile.addEventListener("change", async () => {
  tableErr.textContent = ""; upload = null; tableSave.disabled = true;
  const f = tableFile.files[0]; if (!f) return;
  if (f.size > 900000) { tableErr.textContent = f.name + ": too large (at most 900 kB here)"; return; }
  upload = {name: f.name, text: await f.text()}; tableSave.disabled = false;
});
tableSave.addEventListener("click", async () => {
  if (!upload) return;
  tableSave.disabled = true;  // one click, one file: choose the next one again
  let out;
  try { out = await answer(await post("/api/table", {values: {}, table: upload})); } catch (err) { out = unreachable(); }
  upload = null; tableFile.value = "";
  if (!out.saved) { tableErr.textContent = (out.errors || [{message: "not saved"}])[0].message; return; }
  tableErr.textContent = "";
  const old = segments.find(s => s.kind === "table");
  edit(() => { segments = [{kind: "table", law: "table", file: out.saved, noise: old ? old.noise : ""}]; }, "f-motion-0-noise");
  status.textContent = `saved ${out.saved} (${out.rows} points) beside the design`; notes++;
});

// ------------------------------------------------------------------ save and build
document.getElementById("save").addEventListener("click", async () => {
  let out;
  try { out = await answer(await post("/api/save", {values: values(), loaded: document.body.dataset.loaded})); } catch (err) { out = unreachable(); }
  if (out.errors) showErrors(out.errors);
  // a refused save stays said where a later analysis does not clear it (it clears the field errors)
  if (out.conflict && out.errors) document.getElementById("notice").textContent = out.errors[0].message;
  if (out.revision) document.body.dataset.loaded = out.revision;  // the file as saved is the one now loaded
  if (out.saved) segments.forEach((s, i) => { s.source = i; });  // the file's tables are now these
  notes++;
  status.textContent = out.saved ? "saved " + out.saved
    : out.conflict ? "not saved: the file changed on disk" : "not saved: fix the fields marked";
});
document.getElementById("build").addEventListener("click", async () => {
  notes++;
  status.textContent = "building the shop files…";
  let response;
  try { response = await post("/api/build", {values: values()}); }
  catch (err) { showErrors(unreachable().errors); notes++; status.textContent = "not built"; return; }
  if (!response.ok) {
    const out = await answer(response); showErrors(out.errors || []); notes++; status.textContent = "not built"; return;
  }
  const blob = await response.blob();
  const link = document.createElement("a");
  link.href = URL.createObjectURL(blob); link.download = document.body.dataset.stem + "-shop-files.zip";
  document.body.appendChild(link); link.click(); link.remove();
  notes++;
  status.textContent = "built: " + link.download;
});

renderSegments();
record();
analyse();
