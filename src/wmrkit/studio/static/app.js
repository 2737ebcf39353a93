// wmrkit studio page. It edits a robot description and draws what the server answers: every kinematic number
// (analysis, wheel commands, ICR, κ map, trajectory) comes from the wmrkit library through /api/*.
"use strict";

const SVGNS = "http://www.w3.org/2000/svg";
const $ = (id) => document.getElementById(id);
const LENGTHS = new Set(["d", "r", "r_r", "b"]);
const ANGLES = new Set(["delta", "gamma"]);
const S = {
  meta: null, desc: null, geometry: null, analysis: null, drive: null, kappa: null, configs: null,
  analysedText: "", configsText: null,  // the descriptions (JSON) the analysis and the configurations are about
  selected: null, selIndex: -1, undo: [], redo: [], twist: [0, 0, 0], heading: {}, path: "",
  inflight: false, pending: false, driving: 0, driveSeq: 0, editTime: 0, seq: 0, anim: null, view: null,
  startError: null,  // the start file could not be read again (invalid or gone): shown over its last good robot
  loadWarnings: [],  // the warnings of the file or catalog robot as read, shown until another is loaded or saved
  descWarnings: [],  // the warnings of the description analysed last (a mecanum wheel whose gamma is not +-45 deg)
  notice: null,  // {name, index, text}: what the last retype of that wheel dropped, shown under its type until an edit
                //   (index -1: what deleting a wheel removed, shown where the wheel's panel was)
};
// Timings for the docs and the browser test: round trip edit -> numbers shown [ms], server time [ms].
window.studioStats = { edits: [], server: [], rendered: 0 };

// ---- server ---------------------------------------------------------------------------------------------------
async function call(path, body) {
  const init = body === undefined ? {} : {
    method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) };
  let r;
  try { r = await fetch(path, init); } catch {  // no answer at all (the server stopped): an error, not a request
    // left in flight for good (every later edit waited behind it, even after the server was back)
    return { ok: false, status: 0, data: { error: `no answer from the studio server (${path}): is it running?` },
      server: null };
  }
  const data = await r.json().catch(() => ({ error: `HTTP ${r.status}` }));
  const timing = (r.headers.get("Server-Timing") || "").match(/dur=([\d.]+)/);
  return { ok: r.ok, status: r.status, data, server: timing ? parseFloat(timing[1]) : null };
}

// ---- units and formatting -------------------------------------------------------------------------------------
const deg = (rad) => rad * 180 / Math.PI;
function fmt(x, digits = 4) {
  if (x === null || x === undefined) return "–";
  if (typeof x !== "number") return String(x);
  if (Math.abs(x) < 5e-13) x = 0;
  return Number(x.toPrecision(digits)).toString();
}
function shownUnit(field) {  // the unit a field shows its value in: mm for lengths, deg for angles, else none
  if (LENGTHS.has(field) || field === "x" || field === "y") return "mm";
  if (ANGLES.has(field) || field === "heading") return "deg";
  return "";
}
function shown(value, field) {  // a description value as the user sees it: numbers (SI) in mm / deg
  if (typeof value !== "number") return value === undefined || value === null ? "" : String(value);
  const unit = shownUnit(field);
  if (unit === "mm") return `${fmt(value * 1000, 6)} mm`;
  if (unit === "deg") return `${fmt(deg(value), 6)} deg`;
  return String(value);
}
const BARE_NUMBER = /^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/;
function typed(field, text) {  // a bare number typed in a field shown in mm or deg is in that unit, as displayed
  const unit = shownUnit(field);
  return unit && BARE_NUMBER.test(text) ? `${text} ${unit}` : text;
}

// A steering range [min, max] (headings) as shown, "-40 deg, 40 deg", and as typed: "[-40, 40]" or "-40 deg, 0.7 rad"
// give the description's list of two headings, bare numbers in deg; anything else goes to the server as typed (a
// list of its comma-separated parts), which says what is wrong on the field, as for a description file.
function shownRange(range) {
  if (range === undefined || range === null) return "";
  return Array.isArray(range) ? range.map((v) => shown(v, "heading")).join(", ") : String(range);
}
function typedRange(text) { return text.replace(/^\[(.*)\]$/s, "$1").split(",").map((p) => typed("heading", p.trim())); }

// ---- editing, undo/redo ---------------------------------------------------------------------------------------
function commit(mutate, { push = true } = {}) {
  S.notice = null;  // said once, after the retype that dropped something (the mutation may set it again)
  const before = JSON.stringify(S.desc);
  const next = JSON.parse(before);
  mutate(next);
  if (JSON.stringify(next) === before) return;
  if (push) { S.undo.push(before); S.redo = []; }
  S.desc = next;
  afterChange();
  refresh();
}
function restore(text) {  // undo, redo: the selection and the driven headings may name wheels that are gone
  S.desc = JSON.parse(text); S.notice = null;
  afterChange();
  renderWheelPanel();
  refresh();
}
function afterChange() {
  if (S.selected !== null && selectedIndex() < 0) S.selected = null;
  S.heading = steeringHeadings(S.heading);
}
function undo() { if (S.undo.length) { S.redo.push(JSON.stringify(S.desc)); restore(S.undo.pop()); } }
function redo() { if (S.redo.length) { S.undo.push(JSON.stringify(S.desc)); restore(S.redo.pop()); } }
function wheelIndex(name) { return Array.isArray(S.desc.wheels) ? S.desc.wheels.findIndex((w) => w.name === name) : -1; }
// The selected wheel is known by its name and its index: while two wheels share the name (a duplicate being
// fixed), the index tells which one (by name alone the other wheel was edited, and the names swapped silently).
function select(name, i = wheelIndex(name)) { S.selected = name; S.selIndex = i; }
function selectedIndex() {
  if (S.selected === null || !Array.isArray(S.desc.wheels)) return -1;
  const w = S.desc.wheels[S.selIndex];
  return w && w.name === S.selected ? S.selIndex : wheelIndex(S.selected);
}
function steeringHeadings(heading) {  // the driven headings of wheels that still steer (a wheel renamed, retyped
  const out = {};                     // or deleted while driving is dropped: /api/drive refuses unknown names)
  const wheels = Array.isArray(S.desc.wheels) ? S.desc.wheels : [];
  for (const [name, h] of Object.entries(heading || {})) {
    const w = wheels.find((x) => x && x.name === name), kind = w && S.meta.kinds[w.type];
    if (kind && kind.steers) out[name] = h;
  }
  return out;
}
// Couplings name joints 'wheel.joint': renaming a wheel rewrites them; deleting it, or a type without the joint
// (or where it changes role: a linkage couples steering angles, the others rates), drops the joint from its
// coupling, and the coupling when fewer than two joints remain. Returns what it removed, for the retype's note.
function rewriteCouplings(d, name, { rename = null, type = undefined } = {}) {
  const removed = [];
  if (!Array.isArray(d.couplings)) return removed;
  const kind = type === undefined ? undefined : type === null ? null : S.meta.kinds[type];
  d.couplings = d.couplings.filter((c) => {
    if (!c || !Array.isArray(c.joints)) return true;
    const ratios = Array.isArray(c.ratios) && c.ratios.length === c.joints.length ? [...c.ratios] : null;
    const joints = [], kept = [];
    let touched = false;
    c.joints.forEach((j, i) => {
      const [wheel, ...rest] = typeof j === "string" ? j.split(".") : [null];
      const part = rest.join(".");
      if (wheel !== name) { joints.push(j); kept.push(i); return; }
      touched = true;
      if (rename !== null) { joints.push(`${rename}.${part}`); kept.push(i); return; }
      if (kind === undefined) { joints.push(j); kept.push(i); return; }
      const angle = kind && part === "steer" && !(kind.rates || []).includes("steer");
      if (kind && kind.joints.includes(part) && angle === (c.kind === "linkage")) { joints.push(j); kept.push(i); }
    });
    if (!touched) return true;
    const gone = c.joints.filter((j, i) => !kept.includes(i)), of = `the ${c.kind} coupling (${c.joints.join(", ")})`;
    if (joints.length < 2) { removed.push(of); return false; }
    if (gone.length) removed.push(`${gone.join(", ")} from ${of}`);
    c.joints = joints;
    if (ratios) c.ratios = kept.map((i) => ratios[i]);
    return true;
  });
  if (!d.couplings.length) delete d.couplings;
  return removed;
}
function geometryOf(name) { return S.geometry && S.geometry.wheels.find((w) => w.name === name); }

function setPlace(w, x, y) { delete w.l; delete w.alpha; w.position = [x, y]; }
function setHeading(w, h) { delete w.beta; w.heading = h; }
// A heading picked with the mouse [rad], in whole hundredths of a degree: "90 deg", not 90.0002 deg (1e-4 rad).
function cleanHeading(rad) { return `${Math.round(deg(rad) * 100) / 100} deg`; }

// ---- analysis on every edit -----------------------------------------------------------------------------------
function refresh() {
  S.editTime = performance.now();
  if (S.inflight) { S.pending = true; return; }
  send();
}
async function send() {
  S.inflight = true; S.pending = false;
  const t0 = S.editTime, seq = ++S.seq, desc = S.desc, text = JSON.stringify(desc);
  const r = await call("/api/analyze", { description: desc });
  S.inflight = false;
  if (r.ok) {
    S.geometry = r.data.geometry; S.analysis = r.data.analysis; S.valid = desc; S.analysedText = text;
    showError(S.startError && { error: S.startError }); S.startError = null;
    S.descWarnings = r.data.warnings; showWarnings();
  } else {
    showError(r.data);
  }
  renderAll();
  window.studioStats.edits.push(performance.now() - t0);
  if (r.server !== null) window.studioStats.server.push(r.server);
  window.studioStats.rendered = seq;
  $("status").textContent = `edit → numbers ${fmt(performance.now() - t0, 3)} ms (server ${fmt(r.server, 3)} ms)`;
  if (S.pending) { send(); return; }
  if (r.ok) { driveNow(); later("configs", loadConfigurations, 350); later("kappa", loadKappa, 250); }
}
const timers = {};
function later(key, fn, ms) { clearTimeout(timers[key]); timers[key] = setTimeout(() => { delete timers[key]; fn(); }, ms); }

// The slow answers (/api/configurations, /api/kappa): one request of each in flight, the latest edit waiting
// (requests do not pile up in the server's threads), and an answer older than the latest request is dropped.
const slow = { configs: { seq: 0, busy: false, again: false }, kappa: { seq: 0, busy: false, again: false } };
async function loadSlow(key, request, show) {
  const q = slow[key];
  if (q.busy) { q.again = true; return; }
  q.busy = true; q.again = false;
  const seq = ++q.seq;
  let r;
  try { r = await request(); } finally { q.busy = false; }
  if (q.again) { loadSlow(key, request, show); return; }  // a newer edit came meanwhile: its answer replaces this
  if (seq !== q.seq || r === undefined) return;
  show(r);
}
function loadConfigurations() {
  let text;  // the description asked about
  const request = () => { text = JSON.stringify(S.desc); return call("/api/configurations", { description: S.desc }); };
  return loadSlow("configs", request, (r) => {
    S.configs = r.ok ? r.data : null; S.configsText = text;
    renderAnalysis();
  });
}
function loadKappa() {
  return loadSlow("kappa", async () => {
    // whether the robot steers is known of the analysed description only: a newer one waits for its analysis, which
    // asks for its map (sent before, omni-3 opened after swerve-4 got '400: does not steer')
    if (S.analysedText !== JSON.stringify(S.desc)) return undefined;
    if (!S.analysis || Object.keys(S.analysis.steering).length === 0) return { ok: false, data: null };
    return call("/api/kappa", { description: S.desc, resolution: 72 });
  }, (r) => {
    S.kappa = r.ok ? r.data : null;
    renderKappa();
  });
}
async function driveNow() {
  const seq = ++S.driveSeq;
  S.driving += 1;
  S.heading = steeringHeadings(S.heading);
  const r = await call("/api/drive", { description: S.desc, twist: S.twist, heading: S.heading })
    .finally(() => { S.driving -= 1; });
  if (seq !== S.driveSeq) return;  // a newer twist or edit was sent meanwhile
  if (!r.ok) { S.drive = null; renderDrive(); return; }
  S.drive = r.data;
  // the wheels stay where the last twist put them, except beyond their steering range (the twist was infeasible:
  // kept there, a robot at rest was drawn past its rack and called infeasible after Stop)
  if (S.twist.some((v) => v !== 0)) {
    for (const [name, h] of Object.entries(r.data.heading)) if (!r.data.out_of_range.includes(name)) S.heading[name] = h;
  }
  renderDrive(); drawPlan();
}

// ---- errors in place ------------------------------------------------------------------------------------------
function showWarnings() {  // the description's warnings (the CLI's wmrkit: warning: lines), one a line
  const box = $("warnings"), lines = [...S.loadWarnings, ...S.descWarnings];
  box.hidden = !lines.length; box.textContent = lines.map((w) => `warning: ${w}`).join("\n");
}
function showError(err) {
  document.querySelectorAll(".invalid").forEach((e) => e.classList.remove("invalid"));
  document.querySelectorAll("[data-msg]").forEach((e) => { e.textContent = ""; });
  S.error = err;
  const box = $("error");
  if (!err) { box.hidden = true; return; }
  box.hidden = false; box.textContent = errorText(err);
  const w = errorWheel(err), i = w ? err.loc[1] : -1;
  if (w && selectedIndex() !== i) { select(w.name, i); renderWheelPanel(); }
  markField();
}
function errorWheel(err) {  // the wheel an error is about (loc wheels[i]...), when it has a name
  const i = err && err.loc && err.loc[0] === "wheels" && typeof err.loc[1] === "number" ? err.loc[1] : -1;
  const w = i >= 0 && S.desc && Array.isArray(S.desc.wheels) ? S.desc.wheels[i] : null;
  return w && typeof w.name === "string" && w.name ? w : null;
}
function errorText(err) {  // the library's message, the wheel named rather than numbered: wheel 'right', r: ...
  const w = errorWheel(err);
  if (!w || err.message === undefined) return err.error;
  const rest = err.loc.slice(2).map((p) => (typeof p === "number" ? `[${p}]` : `.${p}`)).join("").replace(/^\./, "");
  return `wheel '${w.name}'${rest ? `, ${rest}` : ""}: ${err.message}`;
}
function markField() {
  const err = S.error;
  if (!err || !err.loc || !err.loc.length) return;
  const onWheel = err.loc[0] === "wheels" && err.loc.length >= 3;
  if (err.loc[0] === "wheels" && !onWheel) return;  // about the list or a whole wheel: the box says it
  const scope = onWheel ? $("wheel-fields") : $("robot-panel");  // 'name' is a field of both panels
  let key = onWheel ? err.loc[2] : err.loc[0];
  if (key === "position" || key === "l" || key === "alpha") key = err.loc[3] === 1 ? "y" : "x";
  if (key === "beta") key = "heading";
  const input = scope.querySelector(`[data-field="${key}"]`) || scope.querySelector(`[data-loc="${key}"]`);
  if (input) input.classList.add("invalid");
  const msg = scope.querySelector(`[data-msg="${key}"]`);
  if (msg) msg.textContent = err.message;
}

// ---- side panel: the selected wheel ---------------------------------------------------------------------------
function renderWheelPanel() {
  const box = $("wheel-fields");
  const i = selectedIndex();
  $("wheel-title").textContent = i < 0 ? "" : S.selected;
  if (i < 0) {
    box.innerHTML = '<p class="hint">click a wheel</p>';
    if (S.notice && S.notice.index < 0) {  // what deleting a wheel removed with it
      const n = document.createElement("div"); n.className = "msg note"; n.dataset.note = "delete";
      n.textContent = S.notice.text; box.appendChild(n);
    }
    return;
  }
  const w = S.desc.wheels[i], g = geometryOf(w.name), kind = S.meta.kinds[w.type];
  box.innerHTML = "";
  const row = (label, field, value, title = "") => {
    const l = document.createElement("label"); l.className = "row"; l.textContent = label;
    const input = document.createElement("input");
    input.dataset.field = field; input.value = value; input.title = title;
    input.addEventListener("change", () => editField(field, typed(field, input.value.trim())));
    l.appendChild(input); box.appendChild(l);
    const m = document.createElement("div"); m.className = "msg"; m.dataset.msg = field; box.appendChild(m);
  };
  row("name", "name", w.name);
  const l = document.createElement("label"); l.className = "row"; l.textContent = "type";
  const sel = document.createElement("select"); sel.dataset.field = "type";
  for (const t of Object.keys(S.meta.kinds)) sel.add(new Option(t, t, false, t === w.type));
  if (!(w.type in S.meta.kinds)) sel.add(new Option(String(w.type), String(w.type), false, true));
  sel.addEventListener("change", () => changeType(sel.value));
  l.appendChild(sel); box.appendChild(l);
  const tm = document.createElement("div"); tm.className = "msg"; tm.dataset.msg = "type"; box.appendChild(tm);
  if (S.notice && S.notice.index === i && S.notice.name === w.name) {  // what the retype dropped
    const n = document.createElement("div"); n.className = "msg note"; n.dataset.note = "type";
    n.textContent = S.notice.text; box.appendChild(n);
  }
  const pos = Array.isArray(w.position) ? w.position : (g ? g.joint : [0, 0]);
  row("x", "x", shown(pos[0], "x"), "forward, from the robot origin");
  row("y", "y", shown(pos[1], "y"), "left, from the robot origin");
  const heading = "heading" in w ? w.heading : (g ? g.heading : 0);
  row(kind && kind.steers ? "heading" : "heading (axle ⟂)", "heading", shown(heading, "heading"),
    "rolling direction: 0 = straight ahead (+x), counter-clockwise positive");
  if (kind && kind.steers) row("steer range", "steer_range", shownRange(w.steer_range),
    "min, max headings the steering reaches (0 = straight ahead), e.g. -90, 90; empty: no limit");
  for (const f of kind ? [...kind.required, ...Object.keys(kind.optional)] : []) {
    if (f === "beta") continue;
    row(f, f, shown(f in w ? w[f] : kind.optional[f], f));
  }
  if (!kind) return;
  for (const group of ["actuated", "sensed"]) {
    const div = document.createElement("div"); div.className = "joints"; div.textContent = `${group}:`;
    const have = new Set(typeof w[group] === "string" ? [w[group]] : (w[group] || []));
    for (const j of kind.joints) {
      const c = document.createElement("label");
      const box2 = document.createElement("input"); box2.type = "checkbox"; box2.checked = have.has(j);
      box2.dataset.field = `${group}.${j}`;
      box2.addEventListener("change", () => commit((d) => {
        const ww = d.wheels[i];
        const set = new Set(typeof ww[group] === "string" ? [ww[group]] : (ww[group] || []));
        if (box2.checked) set.add(j); else set.delete(j);
        ww[group] = kind.joints.filter((x) => set.has(x));
        if (!ww[group].length) delete ww[group];
      }));
      c.appendChild(box2); c.append(` ${j}`); div.appendChild(c);
    }
    box.appendChild(div);
  }
  markField();
}
function editField(field, text) {
  const name = S.selected, i = selectedIndex();
  if (i < 0) return;
  commit((d) => {
    const w = d.wheels[i];
    if (field === "name") {
      // the joints and driven heading follow the wheel, unless either name is another wheel's (a duplicate)
      const shared = d.wheels.some((x, k) => k !== i && x && (x.name === name || x.name === text));
      w.name = text; select(text, i);
      if (shared) return;
      rewriteCouplings(d, name, { rename: text });
      if (name in S.heading && text !== name) { S.heading[text] = S.heading[name]; delete S.heading[name]; }
      return;
    }
    if (field === "x" || field === "y") {
      const g = geometryOf(name), pos = Array.isArray(w.position) ? [...w.position] : (g ? [...g.joint] : [0, 0]);
      pos[field === "x" ? 0 : 1] = text; setPlace(w, pos[0], pos[1]); return;
    }
    if (field === "heading") { setHeading(w, text); delete S.heading[name]; return; }  // drawn as typed
    if (field === "steer_range") { if (text === "") delete w.steer_range; else w.steer_range = typedRange(text); return; }
    if (text === "") delete w[field]; else w[field] = text;
  });
}
// A gamma [rad] a retype to mecanum drops, so that the wheel takes it from its quadrant as the reader does: not
// +-45 deg (mod 180 deg) and the wheel (as read, g) has a quadrant (on an axis it needs its gamma; the page warns).
function offMecanumRollers(gamma, g) {
  if (typeof gamma !== "number" || !g) return false;
  const [x, y] = g.joint, rem = gamma - Math.PI * Math.round(gamma / Math.PI);
  return Math.abs(Math.abs(rem) - Math.PI / 4) > 1e-6 && Math.abs(x * y) > 1e-12 * (x * x + y * y);
}
function changeType(type) {
  const name = S.selected, i = selectedIndex(), kind = S.meta.kinds[type];
  if (i < 0 || !kind) return;
  commit((d) => {
    const old = d.wheels[i], g = geometryOf(name);
    const w = { name: old.name, type };
    setPlace(w, ...(Array.isArray(old.position) ? old.position : (g ? g.joint : [0, 0])));
    w.heading = "heading" in old ? old.heading : (g ? g.heading : 0);
    const r = "r" in old ? old.r : 0.05;
    const defaults = { r, d: 0.04, b: 0.08, gamma: "90 deg", r_r: "10 mm", delta: 0 };
    const read = (g && g.fields) || {};  // as the server read it: a mecanum wheel's gamma from its quadrant
    for (const f of kind.required) if (f !== "beta") w[f] = f in old ? old[f] : f in read ? read[f] : defaults[f];
    const dropped = [];
    for (const [f, v] of Object.entries(old)) {  // every other field the new type takes (/api/meta) is kept
      if (f in w || ["beta", "l", "alpha", "heading", "actuated", "sensed"].includes(f)) continue;
      if (!kind.fields.includes(f)) {
        dropped.push(f === "steer_range" ? `steer_range [${shownRange(v)}] (a ${type} wheel does not steer)` : f);
      } else if (f === "inertia" && v && typeof v === "object" && !Array.isArray(v)) {  // the joints it has
        const keep = Object.keys(v).filter((j) => kind.inertia.includes(j));
        if (keep.length) w.inertia = Object.fromEntries(keep.map((j) => [j, v[j]]));
        dropped.push(...Object.keys(v).filter((j) => !keep.includes(j)).map((j) => `inertia ${j}`));
      } else if (f === "gamma" && type === "mecanum" && offMecanumRollers(typeof v === "number" ? v : read.gamma, g)) {
        dropped.push(`gamma ${shown(v, "gamma")} (a mecanum wheel's rollers are at ±45 deg from its quadrant)`);
      } else w[f] = v;  // steer_range: headings, the same stops
    }
    for (const group of ["actuated", "sensed"]) {
      const had = old[group] === undefined ? [] : Array.isArray(old[group]) ? old[group] : [old[group]];
      const keep = had.filter((j) => kind.joints.includes(j));
      if (keep.length) w[group] = keep;
      dropped.push(...had.filter((j) => !keep.includes(j)).map((j) => `${group} ${j}`));
    }
    d.wheels[i] = w;
    const uncoupled = rewriteCouplings(d, name, { type });
    const said = [dropped.length ? `dropped ${dropped.join(", ")}` : "", uncoupled.length ? `removed ${uncoupled.join(", ")}` : ""];
    if (dropped.length || uncoupled.length) S.notice = { name: old.name, index: i, text: `retyped to ${type}: ${said.filter(Boolean).join("; ")}` };
  });
}
function addWheel() {
  const type = $("new-type").value, kind = S.meta.kinds[type];
  let n = S.desc.wheels.length, name;
  do { name = `w${++n}`; } while (wheelIndex(name) >= 0);
  const size = S.geometry ? S.geometry.size : 0.3;
  commit((d) => {
    // a mecanum wheel takes its rollers' angle from its quadrant: not on an axis
    const w = { name, type, position: [type === "mecanum" ? 0.6 * size : 0, 0.6 * size], heading: 0, r: 0.05 };
    if (kind.required.includes("d")) w.d = 0.04;
    if (kind.required.includes("b")) w.b = 0.08;
    if (kind.required.includes("gamma")) { w.gamma = "90 deg"; w.r_r = "10 mm"; }
    d.wheels.push(w);
  });
  select(name); renderWheelPanel();
}
function deleteWheel() {
  const name = S.selected, i = selectedIndex();
  if (i < 0) { S.selected = null; renderWheelPanel(); return; }
  commit((d) => {
    d.wheels.splice(i, 1);
    const uncoupled = rewriteCouplings(d, name, { type: null });
    if (uncoupled.length) S.notice = { name: null, index: -1, text: `deleted ${name}: removed ${uncoupled.join(", ")}` };
  });
  S.selected = null; renderWheelPanel();
}

// ---- plan view ------------------------------------------------------------------------------------------------
function el(tag, attrs, parent) {
  const e = document.createElementNS(SVGNS, tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (parent) parent.appendChild(e);
  return e;
}
function viewBox() {
  const pts = [[0, 0]];
  for (const w of S.geometry.wheels) { pts.push(w.joint); for (const e of w.elements) pts.push(e.centre); }
  if (S.anim && S.drive) for (const p of S.drive.poses) pts.push([p[0], p[1]]);
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const rMax = Math.max(...S.geometry.wheels.flatMap((w) => w.elements.map((e) => e.r)));
  const pad = 0.35 * Math.max(S.geometry.size, 0.2) + rMax;
  let x0 = Math.min(...xs) - pad, x1 = Math.max(...xs) + pad, y0 = Math.min(...ys) - pad, y1 = Math.max(...ys) + pad;
  const svg = $("plan"), ratio = svg.clientWidth / Math.max(svg.clientHeight, 1);
  const w = x1 - x0, h = y1 - y0;
  if (w / h < ratio) { const e = (h * ratio - w) / 2; x0 -= e; x1 += e; } else { const e = (w / ratio - h) / 2; y0 -= e; y1 += e; }
  return [x0, y0, x1 - x0, y1 - y0];
}
function drawPlan(pose) {
  const svg = $("plan");
  if (!S.geometry) return;
  if (!S.view || !S.dragging) S.view = viewBox();
  const [x0, y0, w, h] = S.view;
  svg.setAttribute("viewBox", `${x0} ${-(y0 + h)} ${w} ${h}`);  // y up: the drawing is mirrored below
  svg.innerHTML = "";
  const world = el("g", { transform: "scale(1,-1)" }, svg);
  const unit = w / svg.clientWidth;  // metres per pixel
  drawGrid(world, x0, y0, w, h);
  if (S.anim && S.drive) el("polyline", { points: S.drive.poses.map((p) => `${p[0]},${p[1]}`).join(" "),
    fill: "none", stroke: "#9aa9b8", "stroke-dasharray": "4 4", class: "thin" }, world);
  const body = el("g", pose ? { transform: `translate(${pose[0]},${pose[1]}) rotate(${deg(pose[2])})` } : {}, world);
  drawFrame(body, unit);
  const near = S.analysis && Object.values(S.analysis.singular_here).some((s) => s.near);
  for (const wg of S.geometry.wheels) drawWheel(body, wg, unit, near);
  drawIcr(body, unit);
}
function drawGrid(g, x0, y0, w, h) {
  const step = Math.pow(10, Math.floor(Math.log10(Math.max(w, h) / 4))) / 2;
  for (let x = Math.ceil(x0 / step) * step; x < x0 + w; x += step)
    el("line", { x1: x, y1: y0, x2: x, y2: y0 + h, stroke: "#f0f0f0", class: "thin" }, g);
  for (let y = Math.ceil(y0 / step) * step; y < y0 + h; y += step)
    el("line", { x1: x0, y1: y, x2: x0 + w, y2: y, stroke: "#f0f0f0", class: "thin" }, g);
}
function drawFrame(g, unit) {
  const L = 40 * unit;
  el("line", { x1: 0, y1: 0, x2: L, y2: 0, stroke: "#d62728", "stroke-width": 2, class: "thin" }, g);
  el("line", { x1: 0, y1: 0, x2: 0, y2: L, stroke: "#2ca02c", "stroke-width": 2, class: "thin" }, g);
  el("circle", { cx: 0, cy: 0, r: 3 * unit, fill: "#222" }, g);
}
function arrow(g, from, angle, length, color, unit) {
  const to = [from[0] + length * Math.cos(angle), from[1] + length * Math.sin(angle)];
  el("line", { x1: from[0], y1: from[1], x2: to[0], y2: to[1], stroke: color, "stroke-width": 2.5, class: "thin" }, g);
  const s = Math.sign(length) || 1, hd = 8 * unit;
  for (const side of [-1, 1]) {
    const a = angle + (s > 0 ? Math.PI : 0) + side * 0.45;
    el("line", { x1: to[0], y1: to[1], x2: to[0] + hd * Math.cos(a), y2: to[1] + hd * Math.sin(a),
      stroke: color, "stroke-width": 2.5, class: "thin" }, g);
  }
}
function drawWheel(parent, wg, unit, near) {
  const cmd = S.drive && S.drive.wheels[wg.name];
  const g = el("g", { class: "wheel" + (wg.name === S.selected ? " selected" : "") + (near ? " singular-near" : ""),
    "data-wheel": wg.name }, parent);
  const driven = (j) => wg.actuated.includes(j);
  const turn = cmd && wg.steers ? cmd.heading - wg.heading : 0;  // shown at the commanded heading while driving
  const rot = (p) => {
    const dx = p[0] - wg.joint[0], dy = p[1] - wg.joint[1], c = Math.cos(turn), s = Math.sin(turn);
    return [wg.joint[0] + c * dx - s * dy, wg.joint[1] + s * dx + c * dy];
  };
  const width = Math.max(0.4 * Math.max(...wg.elements.map((e) => e.r)), 6 * unit);
  for (const e of wg.elements) {
    const c = rot(e.centre), axle = e.axle + turn, roll = axle + Math.PI / 2;
    const ax = [Math.cos(axle), Math.sin(axle)], ro = [Math.cos(roll), Math.sin(roll)];
    const reach = width / 2 + 0.9 * e.r;
    el("line", { x1: c[0] - reach * ax[0], y1: c[1] - reach * ax[1], x2: c[0] + reach * ax[0], y2: c[1] + reach * ax[1],
      class: "axle" }, g);
    const face = driven(e.spin_joint) ? "#f28e2b" : "#e6e6e6";
    const cls = "tyre" + (wg.sensed.includes(e.spin_joint) ? " sensed" : "");
    if (wg.type === "ball") el("circle", { cx: c[0], cy: c[1], r: e.r, fill: face, class: cls }, g);
    else el("rect", { x: -e.r, y: -width / 2, width: 2 * e.r, height: width, fill: face, class: cls,
      transform: `translate(${c[0]},${c[1]}) rotate(${deg(roll)})` }, g);
    if (e.roller !== null) {
      const rel = e.roller - e.axle, dir = [Math.cos(e.roller + turn), Math.sin(e.roller + turn)];
      const half = Math.min(0.45 * width / Math.max(Math.abs(Math.cos(rel)), 1e-9), 0.3 * e.r / Math.max(Math.abs(Math.sin(rel)), 1e-9));
      for (const t of [-0.6, -0.2, 0.2, 0.6]) {
        const m = [c[0] + t * e.r * ro[0], c[1] + t * e.r * ro[1]];
        el("line", { x1: m[0] - half * dir[0], y1: m[1] - half * dir[1], x2: m[0] + half * dir[0], y2: m[1] + half * dir[1],
          stroke: "#222", class: "thin" }, g);
      }
    }
  }
  if (wg.type === "castor" || wg.type === "double_castor") {
    const cs = wg.elements.map((e) => rot(e.centre));
    const mid = [cs.reduce((a, p) => a + p[0], 0) / cs.length, cs.reduce((a, p) => a + p[1], 0) / cs.length];
    el("line", { x1: wg.joint[0], y1: wg.joint[1], x2: mid[0], y2: mid[1], stroke: "#222", "stroke-width": 3, class: "thin" }, g);
  }
  if (wg.elements.length === 2) {
    const [a, b] = wg.elements.map((e) => rot(e.centre));
    el("line", { x1: a[0], y1: a[1], x2: b[0], y2: b[1], stroke: "#222", "stroke-width": 3, class: "thin" }, g);
  }
  if (wg.steers) el(driven("steer") ? "rect" : "circle", driven("steer")
    ? { x: wg.joint[0] - 4 * unit, y: wg.joint[1] - 4 * unit, width: 8 * unit, height: 8 * unit, fill: "#f28e2b", stroke: "#222", class: "thin" }
    : { cx: wg.joint[0], cy: wg.joint[1], r: 4 * unit, fill: "#fff", stroke: "#222", class: "thin" }, g);
  // name (un-mirrored)
  const label = el("text", { x: wg.joint[0] + 6 * unit, y: -(wg.joint[1] + 6 * unit), transform: "scale(1,-1)",
    "font-size": 11 * unit, fill: "#555" }, g);
  label.textContent = wg.name;
  if (cmd && cmd.speed !== null && Math.abs(cmd.speed) > 1e-9) {
    const c = wg.elements.length === 1 ? rot(wg.elements[0].centre) : wg.joint;
    arrow(g, c, cmd.heading, cmd.speed * 0.5 * Math.max(S.geometry.size, 0.2),
      Math.abs(cmd.slip) > 1e-9 ? "#c62828" : "#1565c0", unit);
  }
  if (wg.name === S.selected) {  // rotate handle: along the heading
    const hl = Math.max(2.2 * Math.max(...wg.elements.map((e) => e.r)), 30 * unit);
    const hp = [wg.joint[0] + hl * Math.cos(wg.heading), wg.joint[1] + hl * Math.sin(wg.heading)];
    el("line", { x1: wg.joint[0], y1: wg.joint[1], x2: hp[0], y2: hp[1], stroke: "#7b1fa2", class: "thin" }, g);
    el("circle", { cx: hp[0], cy: hp[1], r: 6 * unit, class: "handle", "data-handle": wg.name }, g);
  }
}
function drawIcr(g, unit) {
  const icr = S.drive && S.drive.icr;
  if (!icr || icr.kind !== "point") return;
  const [x, y] = icr.point, s = 7 * unit;
  el("path", { d: `M${x - s},${y - s}L${x + s},${y + s}M${x - s},${y + s}L${x + s},${y - s}`, stroke: "#c62828",
    "stroke-width": 2.5, class: "thin", "data-icr": "" }, g);
}
function svgPoint(ev) {
  const svg = $("plan"), p = svg.createSVGPoint();
  p.x = ev.clientX; p.y = ev.clientY;
  const q = p.matrixTransform(svg.getScreenCTM().inverse());
  return [q.x, -q.y];
}
function onPointerDown(ev) {
  const handle = ev.target.closest("[data-handle]"), wheel = ev.target.closest("[data-wheel]");
  if (!handle && !wheel) return;
  const name = handle ? handle.dataset.handle : wheel.dataset.wheel;
  if (S.selected !== name) { select(name); renderWheelPanel(); drawPlan(); }
  const g = geometryOf(name), start = svgPoint(ev);
  S.dragging = { name, rotate: !!handle, offset: [g.joint[0] - start[0], g.joint[1] - start[1]], joint: g.joint,
    before: JSON.stringify(S.desc), pushed: false };  // one undo step, pushed when the drag first moves
  $("plan").setPointerCapture(ev.pointerId);
  ev.preventDefault();
}
function onPointerMove(ev) {
  const d = S.dragging;
  if (!d) return;
  const p = svgPoint(ev), round = (v) => Math.round(v * 1e4) / 1e4;
  if (wheelIndex(d.name) < 0) return;
  commit((desc) => {
    const w = desc.wheels[wheelIndex(d.name)];
    if (d.rotate) {  // the wheel is drawn where the handle turns it, not at the heading a twist left
      setHeading(w, cleanHeading(Math.atan2(p[1] - d.joint[1], p[0] - d.joint[0])));
      delete S.heading[d.name];
    }
    else setPlace(w, round(p[0] + d.offset[0]), round(p[1] + d.offset[1]));
  }, { push: false });
  if (!d.pushed && JSON.stringify(S.desc) !== d.before) { d.pushed = true; S.undo.push(d.before); S.redo = []; }
}
function onPointerUp() {
  if (!S.dragging) return;
  S.dragging = null;
  renderWheelPanel(); drawPlan();
}

// ---- analysis panel -------------------------------------------------------------------------------------------
function setCell(id, html, value) {
  const c = $(id); c.innerHTML = html;
  if (value !== undefined) c.dataset.value = JSON.stringify(value);
}
function renderAnalysis() {
  const a = S.analysis;
  if (!a) return;
  setCell("a-type", a.type === null ? '<span class="bad">none (degenerate)</span>' : `type ${a.type}: ${a.type_name}`, a.type);
  setCell("a-ms", `m = ${a.mobility}, s = ${a.steerability}` +
    (a.instantaneous_mobility !== a.mobility ? ` (here m = ${a.instantaneous_mobility})` : "") +
    (a.coordinated_steering ? "; steering must be coordinated" : "") +
    (a.commanded_steerability < a.steerability ? `; its steering linkages command s = ${a.commanded_steerability}` : "") +
    // what `wmrkit analyze` says of the type beyond the wheels' m and s (the m gears leave, the ICRs linkages
    // leave), then the steering configurations where m is higher, as it prints them under its type line
    a.type_notes.map((n) => `<br><span class="hint">${esc(n)}</span>`).join("") +
    a.special_configurations.map((c) => `<br><span class="hint">${esc(c.description)}</span>`).join(""),
    [a.mobility, a.steerability]);
  setCell("a-degenerate", a.degenerate ? `<span class="bad">yes</span>: ${esc(a.reasons.join("; "))}`
    : '<span class="good">no</span>', a.degenerate);
  setCell("a-icr", esc(a.icr.text), a.icr);
  const verdict = (v, ok) => `<span class="${ok ? "good" : "warn"}">${esc(v.verdict)}</span> <span class="hint">(${esc(v.joints.join(", ") || "nothing declared")})</span>`;
  setCell("a-actuation", verdict(a.actuation, a.actuation.consistent && a.actuation.sufficient), a.actuation);
  setCell("a-sensing", verdict(a.sensing, a.sensing.sufficient), a.sensing);
  // m <= 1 (of the wheels, or left by gear couplings): no two motions to balance, as `wmrkit analyze` says (a null
  // condition number there was shown as "infinite", though the joints determine the twist)
  setCell("a-kappa", (a.isotropy_note !== null ? `isotropy ${esc(a.isotropy_note)} `
    : a.condition_number === null ? "κ infinite (these joints do not determine the twist) "
    : `κ = ${fmt(a.condition_number, 6)} ` + (a.characteristic_length === null ? ""
      : `at D = ${fmt(a.characteristic_length, 4)} m `)) +
    `<span class="hint">(${esc(a.condition_joints.join(", "))})</span>`, [a.condition_number, a.characteristic_length]);
  const here = Object.entries(a.singular_here).map(([k, s]) => `${k}: ` + (s.singular ? '<span class="bad">singular</span>'
    : s.near ? `<span class="warn">near (distance ${fmt(s.distance, 3)})</span>` : `no (distance ${fmt(s.distance, 3)})`));
  setCell("a-singular-here", here.join("<br>"), a.singular_here);
  // The configurations of an earlier robot are not shown next to this one's analysis (a search may take seconds).
  const c = S.configsText === S.analysedText ? S.configs : undefined;
  if (!c) {
    const note = `<span class="hint">${c === undefined ? "computing…" : "not available"}</span>`;
    setCell("a-singular", note, null); setCell("a-isotropic", note, null);
  } else {
    setCell("a-singular", Object.entries(c.singular).map(([k, s]) => `${k}: ${esc(s.text)}` +
      (s.headings.length ? `<br><span class="hint">${namedHeadings(s.variables, s.headings)}</span>` : "")).join("<br>"), c.singular);
    setCell("a-isotropic", !c.isotropic_searched ? `<span class="hint">${esc(c.isotropic_note || "not searched (see the κ map)")}</span>`
      : c.isotropic.length ? namedHeadings(c.isotropic_wheels, c.isotropic.map((i) => i.heading)) : "none", c.isotropic);
  }
}
// Configurations (lists of headings [rad]) with the wheels they are of, as `wmrkit analyze` names a singular set's:
// "headings of (o1, c2, c3): (90, 180, -110), (90, 0, 110) deg" (the first four).
function namedHeadings(names, configs) {
  return `headings of (${names.map(esc).join(", ")}): ` +
    configs.slice(0, 4).map((h) => "(" + h.map((v) => fmt(deg(v), 4)).join(", ") + ")").join(", ") + " deg";
}
function esc(s) { return String(s).replace(/[&<>"]/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;" })[c]); }

// ---- drive ----------------------------------------------------------------------------------------------------
function setTwist(t, { fromSliders = false } = {}) {
  S.twist = t.map((v) => Math.round(v * 100) / 100);
  if (!fromSliders) ["vx", "vy", "omega"].forEach((id, i) => { $(id).value = S.twist[i]; });
  ["vx", "vy", "omega"].forEach((id, i) => { $(`${id}-out`).textContent = `${S.twist[i].toFixed(2)} ${i < 2 ? "m/s" : "rad/s"}`; });
  drawJoystick();
  later("drive", driveNow, 30);
}
function renderDrive() {
  const d = S.drive, tab = $("commands");
  if (!d) { $("d-feasible").textContent = ""; tab.innerHTML = ""; return; }
  const why = [];  // an Ackermann turn beyond the rack was 'the wheels would slip (residual 4.9e-16 m/s)'
  if (d.out_of_range.length) why.push(`${d.out_of_range.join(", ")} beyond the steering range`);
  if (d.out_of_gear.length) why.push(`${d.out_of_gear.join(", ")} cannot turn its joints so`);
  if (d.out_of_steer_gear.length) why.push(`${d.out_of_steer_gear.join(", ")} cannot set these headings`);
  if (d.out_of_linkage.length) why.push(`${d.out_of_linkage.join(", ")} cannot set these headings`);
  if (d.slips || !why.length) why.push(`the wheels would slip (residual ${fmt(d.residual, 3)} m/s)`);
  $("d-feasible").innerHTML = d.feasible ? '<span class="good">feasible: no wheel slips</span>'
    : `<span class="bad">infeasible: ${esc(why.join("; "))}</span>`;
  $("d-feasible").dataset.value = JSON.stringify(d.feasible);
  $("d-icr").textContent = d.icr.text;
  // the columns of `wmrkit ik`: a castor's steer rate (it swivels as the robot moves), "–" where none
  tab.innerHTML = "<tr><th>wheel</th><th>heading [deg]</th><th>spin [rad/s]</th><th>steer rate [rad/s]</th><th>slip [m/s]</th></tr>";
  for (const [name, c] of Object.entries(d.wheels)) {
    const tr = document.createElement("tr"); tr.dataset.wheel = name;
    const joints = Object.entries(c).filter(([k]) => !["heading", "spin", "speed", "steer_rate", "slip"].includes(k))
      .map(([k, v]) => `${esc(k)} ${fmt(v, 4)}`);  // a double wheel's spin1, spin2 (spin: their mean), rollers
    tr.innerHTML = `<td>${esc(name)}</td><td data-value="${c.heading}">${fmt(deg(c.heading), 4)}</td>` +
      `<td data-value="${c.spin}">${fmt(c.spin, 4)}${joints.length ? ` <span class="hint">(${joints.join(", ")})</span>` : ""}</td>` +
      `<td data-value="${c.steer_rate}">${fmt(c.steer_rate, 4)}</td><td class="${Math.abs(c.slip) > 1e-9 ? "bad" : ""}">${fmt(c.slip, 3)}</td>`;
    tab.appendChild(tr);
  }
}
function drawJoystick() {
  const c = $("joystick"), x = c.getContext("2d"), R = c.width / 2;
  x.clearRect(0, 0, c.width, c.height);
  x.strokeStyle = "#9aa9b8"; x.beginPath(); x.arc(R, R, R - 2, 0, 2 * Math.PI); x.moveTo(R, 4); x.lineTo(R, c.height - 4);
  x.moveTo(4, R); x.lineTo(c.width - 4, R); x.stroke();
  const kx = R - S.twist[1] * (R - 14), ky = R - S.twist[0] * (R - 14);  // up = +vx (forward), left = +vy
  x.fillStyle = "#1565c0"; x.beginPath(); x.arc(kx, ky, 12, 0, 2 * Math.PI); x.fill();
}
function joystickAt(ev) {
  const c = $("joystick"), r = c.getBoundingClientRect(), R = r.width / 2;
  let dx = (ev.clientX - r.left - R) / (R - 14), dy = (ev.clientY - r.top - R) / (R - 14);
  const n = Math.hypot(dx, dy); if (n > 1) { dx /= n; dy /= n; }
  setTwist([-dy, -dx, S.twist[2]]);
}
function animate() {
  if (!$("animate").checked || !S.drive) { S.anim = null; drawPlan(); return; }
  if (!S.anim) S.anim = { t0: performance.now() };
  const d = S.drive, T = d.times[d.times.length - 1];
  const t = ((performance.now() - S.anim.t0) / 1000) % T, i = Math.min(Math.floor(t / T * (d.poses.length - 1)), d.poses.length - 1);
  drawPlan(d.poses[i]);
  requestAnimationFrame(animate);
}

// ---- κ map ----------------------------------------------------------------------------------------------------
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
function colour(t) {
  const x = Math.min(Math.max(t, 0), 1) * (VIRIDIS.length - 1), i = Math.min(Math.floor(x), VIRIDIS.length - 2), f = x - i;
  return VIRIDIS[i].map((c, k) => Math.round(c + f * (VIRIDIS[i + 1][k] - c)));
}
function renderKappa() {
  const c = $("kappa"), x = c.getContext("2d"), k = S.kappa;
  x.clearRect(0, 0, c.width, c.height);
  if (!k) { $("k-note").textContent = "only for robots that steer"; return; }
  const n = k.axis.length, vals = k.kappa.map((v) => (v === null ? null : Math.log10(v)));
  const finite = vals.filter((v) => v !== null), hi = Math.min(Math.max(...finite, 0.1), 2);
  const P = 30, W = c.width - P - 4, H = c.height - P - 4;
  if (k.shape.length === 2) {
    const img = x.createImageData(n, n);
    for (let i = 0; i < n; i++) for (let j = 0; j < n; j++) {
      const v = vals[i * n + j], p = 4 * ((n - 1 - j) * n + i), col = v === null ? [200, 200, 200] : colour(v / hi);
      img.data.set([...col, 255], p);
    }
    const tmp = document.createElement("canvas"); tmp.width = n; tmp.height = n; tmp.getContext("2d").putImageData(img, 0, 0);
    x.imageSmoothingEnabled = false; x.drawImage(tmp, P, 4, W, H);
  } else {
    x.strokeStyle = "#1565c0"; x.beginPath();
    vals.forEach((v, i) => { if (v === null) return; const px = P + (i + 0.5) / n * W, py = 4 + H - (v / hi) * H; i ? x.lineTo(px, py) : x.moveTo(px, py); });
    x.stroke();
  }
  const toPx = (h) => P + kappaFraction(h, n) * W, toPy = (h) => 4 + H - kappaFraction(h, n) * H;
  x.strokeStyle = "#fff"; x.lineWidth = 2;
  const cx = toPx(k.current[0]), cy = k.current.length > 1 ? toPy(k.current[1]) : 4 + H / 2;
  x.beginPath(); x.moveTo(cx - 7, cy); x.lineTo(cx + 7, cy); x.moveTo(cx, cy - 7); x.lineTo(cx, cy + 7); x.stroke();
  x.fillStyle = "#333"; x.font = "10px system-ui";
  x.fillText(`${k.wheels[0]} heading: -180 … 180 deg`, P, c.height - 6);
  if (k.wheels.length > 1) { x.save(); x.translate(10, 4 + H); x.rotate(-Math.PI / 2); x.fillText(`${k.wheels[1]} heading`, 0, 0); x.restore(); }
  // m <= 1 (the analysis's note): one motion, κ = 1 wherever the robot moves ("best κ = 1" said it was isotropic)
  const note = S.analysis && S.analysis.isotropy_note;
  $("k-note").textContent = (note ? `isotropy ${note}: κ = 1 wherever the robot can move`
    : `log10 κ from 0 (isotropic, yellow at ${fmt(hi, 2)})`) + "; grey: the robot cannot move or the model is singular" +
    (k.best && !note ? `; best κ = ${fmt(k.best.kappa, 4)}` : "") + ". Click to steer there.";
}
// Cell i of the map shows κ at axis[i] = -π + 2π i / n and spans [i, i + 1) / n of the axis: headings are placed at
// cell centres (h = axis[i] at (i + 0.5) / n), by the cross and by clicks alike.
function kappaFraction(h, n) { return (((h + Math.PI) / (2 * Math.PI) + 0.5 / n) % 1 + 1) % 1; }
function kappaHeading(fraction, n) { const a = (fraction - 0.5 / n) * 2 * Math.PI - Math.PI; return Math.atan2(Math.sin(a), Math.cos(a)); }
function kappaClick(ev) {
  const k = S.kappa; if (!k) return;
  const c = $("kappa"), r = c.getBoundingClientRect(), sx = c.width / r.width, sy = c.height / r.height;
  const P = 30, W = c.width - P - 4, H = c.height - P - 4, n = k.axis.length;
  const h0 = kappaHeading(((ev.clientX - r.left) * sx - P) / W, n), h1 = kappaHeading((4 + H - (ev.clientY - r.top) * sy) / H, n);
  commit((d) => {
    const i0 = d.wheels.findIndex((w) => w.name === k.wheels[0]), i1 = d.wheels.findIndex((w) => w.name === k.wheels[1]);
    if (i0 >= 0) setHeading(d.wheels[i0], cleanHeading(h0));
    if (k.wheels.length > 1 && i1 >= 0) setHeading(d.wheels[i1], cleanHeading(h1));
  });
  S.heading = {};
}

// ---- files ----------------------------------------------------------------------------------------------------
async function openRobot() {
  const file = $("files").value;
  if (!file && !$("catalog").value) return;
  const r = await call("/api/open", file ? { path: file } : { catalog: $("catalog").value });
  // The error is about the file's wheels, not the robot on screen: its message (naming the file), no field marked.
  if (!r.ok) { showError({ error: r.data.error }); return; }
  load(r.data.description, file || `${r.data.description.name}.yaml`, r.data.warnings);
}
async function saveRobot() {
  const path = $("save-path").value.trim();
  let r = await call("/api/save", { path, description: S.desc });
  if (r.status === 409 && r.data.exists) {  // the file exists: replace it only when the user says so
    if (!window.confirm(`${path} exists in the studio's folder. Replace it?`)) { $("status").textContent = "not saved"; return; }
    r = await call("/api/save", { path, description: S.desc, overwrite: true });
  }
  if (!r.ok) { showError(r.data); return; }
  showError(null);
  S.loadWarnings = []; showWarnings();  // the file loaded is not what it was: its warnings no longer hold
  $("status").textContent = `saved ${r.data.path}`;
  const f = await call("/api/files");
  if (f.ok) fillFiles(f.data.files);
}
function fillFiles(files) {
  const sel = $("files"), keep = sel.value;
  sel.length = 1;
  for (const f of files) sel.add(new Option(f, f, false, f === keep));
}
function load(desc, path, warnings = []) {
  S.loadWarnings = warnings; S.desc = desc; S.undo = []; S.redo = []; S.selected = null; S.heading = {}; S.view = null;
  $("save-path").value = path;
  $("robot-name").value = desc.name;
  renderWheelPanel();
  refresh();
}

// ---- wiring ---------------------------------------------------------------------------------------------------
function renderAll() {
  $("robot-name").value = S.desc.name;
  renderWheelPanel(); renderAnalysis(); drawPlan();
  markField();
}
async function main() {
  const m = await call("/api/meta");
  S.meta = m.data;
  const fromCatalog = S.meta.catalog.includes(S.meta.start.spec);
  $("catalog").add(new Option("(choose)", "", false, !fromCatalog));  // always: choosing a file clears it
  for (const n of S.meta.catalog) $("catalog").add(new Option(n, n, false, n === S.meta.start.spec));
  for (const t of Object.keys(S.meta.kinds)) $("new-type").add(new Option(t, t));
  fillFiles(S.meta.files);
  // Open opens what was chosen last: choosing in one list clears the other (a file chosen before took precedence,
  // and a catalog robot chosen after it was ignored)
  $("catalog").addEventListener("change", () => { if ($("catalog").value) $("files").value = ""; });
  $("files").addEventListener("change", () => { if ($("files").value) $("catalog").value = ""; });
  $("open").onclick = openRobot; $("save").onclick = saveRobot;
  $("undo").onclick = undo; $("redo").onclick = redo;
  $("add").onclick = addWheel; $("delete").onclick = deleteWheel;
  $("robot-name").addEventListener("change", () => commit((d) => { d.name = $("robot-name").value; }));
  const svg = $("plan");
  svg.addEventListener("pointerdown", onPointerDown);
  svg.addEventListener("pointermove", onPointerMove);
  svg.addEventListener("pointerup", onPointerUp);
  svg.addEventListener("pointercancel", onPointerUp);
  for (const id of ["vx", "vy", "omega"]) $(id).addEventListener("input", () =>
    setTwist(["vx", "vy", "omega"].map((k) => parseFloat($(k).value)), { fromSliders: true }));
  $("stop").onclick = () => setTwist([0, 0, 0]);
  $("animate").onchange = () => { S.anim = null; S.view = null; animate(); };
  const js = $("joystick");
  js.addEventListener("pointerdown", (e) => { js.setPointerCapture(e.pointerId); S.stick = true; joystickAt(e); });
  js.addEventListener("pointermove", (e) => { if (S.stick) joystickAt(e); });
  js.addEventListener("pointerup", () => { S.stick = false; });
  $("kappa").addEventListener("click", kappaClick);
  window.addEventListener("resize", () => { S.view = null; drawPlan(); });
  document.addEventListener("keydown", (e) => {
    if (e.target.closest("input, select")) return;
    if ((e.ctrlKey || e.metaKey) && !e.altKey && e.key.toLowerCase() === "z") { undo(); e.preventDefault(); return; }
    if ((e.ctrlKey || e.metaKey) && !e.altKey && e.key.toLowerCase() === "y") { redo(); e.preventDefault(); return; }
    if (e.ctrlKey || e.metaKey || e.altKey) return;  // the browser's shortcuts (Ctrl+A, Ctrl+S, ...): not the twist
    const steps = { w: [0.1, 0, 0], s: [-0.1, 0, 0], a: [0, 0.1, 0], d: [0, -0.1, 0], q: [0, 0, 0.2], e: [0, 0, -0.2] };
    const k = e.key.toLowerCase();
    // within the sliders' own range (vx, vy +-1 m/s, ω +-2 rad/s): a key took vx to 2 while its slider showed 1,
    // and moving another slider then set vx back to 1 silently
    const range = (i) => $(["vx", "vy", "omega"][i]);
    if (k in steps) setTwist(S.twist.map((v, i) => Math.max(+range(i).min, Math.min(+range(i).max, v + steps[k][i]))));
    else if (k === " ") { setTwist([0, 0, 0]); e.preventDefault(); }
    else if (k === "delete") deleteWheel();
  });
  setTwist([0, 0, 0]);
  S.startError = S.meta.start.error || null;
  load(S.meta.start.description, /\.(ya?ml|json)$/i.test(S.meta.start.spec)  // a file: .yaml, .yml, .json (files.py)
    ? S.meta.start.spec : `${S.meta.start.description.name}.yaml`, S.meta.start.warnings);
}
main();
