"use strict";
const form = document.getElementById("design-form");
const status = document.getElementById("status");
// The per-run token the server printed in the page's address: sent with every API call.
const TOKEN = new URLSearchParams(location.search).get("token") || "";
let sent = 0, drawn = 0, timer = null, waiting = false;

function settle() {  // "1" while a change is not yet drawn (tests and screen readers wait on it)
  document.body.dataset.busy = waiting || drawn !== sent ? "1" : "0";
}
const NS = "http://www.w3.org/2000/svg";
const COLORS = ["#1f5f9e", "#d9731a", "#2e8b57", "#a23b72", "#6c5b7b", "#8c6d1f", "#3b8ea5", "#b03a2e"];

function values() {
  const out = {};
  for (const el of form.querySelectorAll("input, select")) out[el.name] = el.value;
  return out;
}
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
function niceStep(span) {
  const raw = span / 5, mag = Math.pow(10, Math.floor(Math.log10(raw)));
  for (const m of [1, 2, 2.5, 5, 10]) if (m * mag >= raw) return m * mag;
  return 10 * mag;
}
function fmt(v) { return Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(1) : +v.toPrecision(4) + ""; }

function drawChart(box, chart, phi) {
  const W = 360, H = 190, L = 52, R = 16, T = 8, B = 26;
  const svg = el("svg", {viewBox: `0 0 ${W} ${H}`, role: "img", "aria-label": chart.title});
  let lo = Infinity, hi = -Infinity;
  for (const s of chart.series) for (const y of s.y) if (y !== null) { lo = Math.min(lo, y); hi = Math.max(hi, y); }
  svg.dataset.ymin = lo; svg.dataset.ymax = hi;
  for (const y of chart.limits || []) { lo = Math.min(lo, y); hi = Math.max(hi, y); }
  if (!isFinite(lo)) { lo = -1; hi = 1; }
  if (hi - lo < 1e-9 * Math.max(1, Math.abs(hi))) { lo -= 1; hi += 1; }
  const pad = 0.06 * (hi - lo); lo -= pad; hi += pad;
  const X = x => L + (W - L - R) * x / 360, Y = y => T + (H - T - B) * (hi - y) / (hi - lo);
  const step = niceStep(hi - lo);
  for (let t = Math.ceil(lo / step) * step; t <= hi; t += step) {
    el("line", {x1: L, x2: W - R, y1: Y(t), y2: Y(t), stroke: Math.abs(t) < step * 1e-6 ? "#666" : "#e3e3e3", "stroke-width": 0.7}, svg);
    const label = el("text", {x: L - 4, y: Y(t) + 3.5, "text-anchor": "end", "font-size": 10, fill: "#444"}, svg);
    label.textContent = fmt(Math.abs(t) < step * 1e-6 ? 0 : t);
  }
  for (let a = 0; a <= 360; a += 90) {
    el("line", {x1: X(a), x2: X(a), y1: T, y2: H - B, stroke: "#eeeeee", "stroke-width": 0.7}, svg);
    const label = el("text", {x: X(a), y: H - B + 13, "text-anchor": "middle", "font-size": 10, fill: "#444"}, svg);
    label.textContent = a + "°";
  }
  for (const y of chart.limits || []) {
    el("line", {x1: L, x2: W - R, y1: Y(y), y2: Y(y), stroke: "#c0392b", "stroke-dasharray": "5 3", "stroke-width": 1}, svg);
  }
  chart.series.forEach((s, k) => {
    let d = "", pen = false;
    s.y.forEach((y, i) => {
      if (y === null || phi[i] === null) { pen = false; return; }
      d += (pen ? "L" : "M") + X(phi[i]).toFixed(2) + " " + Y(y).toFixed(2); pen = true;
    });
    el("path", {d, fill: "none", stroke: COLORS[k % COLORS.length], "stroke-width": 1.3, "data-series": s.label}, svg);
  });
  el("rect", {x: L, y: T, width: W - L - R, height: H - T - B, fill: "none", stroke: "#888", "stroke-width": 0.8}, svg);
  box.replaceChildren(svg);
}

function drawCam(box, d) {
  let reach = d.profile_radius_max;
  for (const f of d.followers) for (const part of [...f.body, ...f.links]) for (const p of part) reach = Math.max(reach, Math.hypot(p[0], p[1]));
  const lim = 1.15 * reach;
  const svg = el("svg", {viewBox: `${-lim} ${-lim} ${2 * lim} ${2 * lim}`, role: "img", "aria-label": "cam drawing"});
  svg.dataset.profileRadiusMax = d.profile_radius_max;
  svg.dataset.baseRadius = d.base_radius;
  const g = el("g", {transform: "scale(1,-1)"}, svg);
  const w = lim / 250;
  el("path", {id: "cam-profile", d: pathOf(d.profile, true), fill: "#dbe6f1", stroke: "#1f3b57", "stroke-width": 2 * w}, g);
  if (d.bore.length) el("path", {d: pathOf(d.bore, true), fill: "#fff", stroke: "#1f3b57", "stroke-width": 1.5 * w}, g);
  el("path", {d: pathOf(d.trace, true), fill: "none", stroke: "#d9731a", "stroke-dasharray": `${6 * w} ${4 * w}`, "stroke-width": 1.3 * w}, g);
  el("circle", {cx: 0, cy: 0, r: d.base_radius, fill: "none", stroke: "#7f7f7f", "stroke-dasharray": `${2 * w} ${3 * w}`, "stroke-width": w}, g);
  d.followers.forEach((f, k) => {
    const c = COLORS[(k + 1) % COLORS.length];
    for (const p of f.body) el("path", {d: pathOf(p, false), fill: "none", stroke: c, "stroke-width": 2 * w}, g);
    for (const p of f.links) el("path", {d: pathOf(p, false), fill: "none", stroke: c, "stroke-width": 2.6 * w}, g);
    for (const p of f.axes) el("path", {d: pathOf(p, false), fill: "none", stroke: c, "stroke-width": 0.8 * w, "stroke-dasharray": `${8 * w} ${3 * w}`}, g);
    const t = el("text", {x: f.label_at[0], y: -f.label_at[1], "font-size": 11 * w * 1.6, fill: c, "text-anchor": "middle"}, svg);
    t.textContent = "φ = " + f.phi_deg + "°";
  });
  box.replaceChildren(svg);
}

function showErrors(errors) {
  for (const span of form.querySelectorAll(".err")) span.textContent = "";
  for (const input of form.querySelectorAll("[aria-invalid]")) input.removeAttribute("aria-invalid");
  const general = document.getElementById("general-error");
  general.textContent = "";
  for (const e of errors) {
    const span = [...form.querySelectorAll(".err")].find(s => s.dataset.for === e.field);
    if (span) {
      span.textContent = e.message;
      const input = document.getElementById(span.id.slice(0, -4));
      input.setAttribute("aria-invalid", "true");
      const box = input.closest("details"); if (box) box.open = true;
    } else {
      general.textContent = (e.field ? e.field + ": " : "") + e.message;
    }
  }
}

function render(out) {
  showErrors(out.errors);
  if (out.ok) {
    document.getElementById("alerts").innerHTML = out.alerts;
    document.getElementById("cards").innerHTML = out.cards;
    drawCam(document.getElementById("cam-drawing-svg"), out.drawing);
    document.getElementById("cam-caption").textContent = out.drawing.caption;
    for (const chart of out.charts) {
      let box = document.getElementById("chart-" + chart.key);
      if (!box) {
        const fig = document.createElement("figure"); fig.className = "chart";
        fig.innerHTML = "<h3></h3><div></div>"; fig.querySelector("h3").textContent = chart.title + (chart.unit ? " [" + chart.unit + "]" : "");
        box = fig.querySelector("div"); box.id = "chart-" + chart.key;
        document.getElementById("charts").appendChild(fig);
      }
      drawChart(box, chart, out.phi_deg);
    }
  }
  document.body.dataset.state = out.ok ? "ok" : "invalid";
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

async function analyse() {
  waiting = false;
  const id = ++sent;
  const notesBefore = notes;
  settle();
  status.textContent = "analysing…";
  const started = performance.now();
  let out;
  try { out = await answer(await post("/api/analyse", {values: values()})); } catch (err) { out = unreachable(); }
  if (id !== sent) return;  // a newer change is on its way
  render(out);
  drawn = id;
  document.body.dataset.revision = String(id);
  settle();
  if (notes === notesBefore) {
    status.textContent = (out.ok ? "updated" : "invalid input") + " in " + Math.round(performance.now() - started) + " ms";
  }
}

function later(ms) { clearTimeout(timer); waiting = true; settle(); timer = setTimeout(analyse, ms); }
form.addEventListener("input", () => later(150));
form.addEventListener("change", () => later(0));
form.addEventListener("submit", ev => ev.preventDefault());
document.getElementById("save").addEventListener("click", async () => {
  let out;
  try { out = await answer(await post("/api/save", {values: values(), loaded: document.body.dataset.loaded})); } catch (err) { out = unreachable(); }
  if (out.errors) showErrors(out.errors);
  if (out.revision) document.body.dataset.loaded = out.revision;  // the file as saved is the one now loaded
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
analyse();
