// gcodekit VelocityPlot front end: planned speed and commanded feed on a 2D canvas.
//
// The kernel sends at most a few thousand points for the range shown: the raw
// velocity trapezoids (four corners per move: accelerating, cruising,
// decelerating) when they fit, else a per-bin min/max envelope.

const COLORS = { accel: "#2ca02c", cruise: "#1f77b4", decel: "#d62728", planned: "#1f77b4", commanded: "#555" };

function typed(view, Type) {
  if (!view || view.byteLength === 0) return new Type(0);
  return new Type(view.buffer.slice(view.byteOffset, view.byteOffset + view.byteLength));
}

function ticks(lo, hi, count) {
  const span = hi - lo || 1;
  const step0 = span / count;
  const mag = Math.pow(10, Math.floor(Math.log10(step0)));
  const step = [1, 2, 5, 10].map((m) => m * mag).find((s) => s >= step0) || step0;
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) out.push(v);
  return out;
}

function render({ model, el }) {
  el.classList.add("gcodekit-velocity");
  const box = document.createElement("div");
  box.style.cssText = "position:relative;width:100%;min-width:0;font:12px sans-serif;box-sizing:border-box";
  const canvas = document.createElement("canvas");
  canvas.style.cssText = "position:absolute;inset:0;width:100%;height:100%";
  const tip = document.createElement("div");
  tip.className = "gk-tip";
  tip.style.cssText = "position:absolute;display:none;background:rgba(255,255,255,0.92);border:1px solid #bbb;" +
    "padding:2px 5px;pointer-events:none;white-space:nowrap";
  const status = document.createElement("div");
  status.className = "gk-plot-status";
  status.style.cssText = "position:absolute;right:12px;top:4px;color:#666";
  box.append(canvas, tip, status);
  el.append(box);
  const ctx = canvas.getContext("2d");
  const pad = { left: 56, right: 12, top: 26, bottom: 34 };
  const state = { width: 600, frame: 0, data: null };

  function load() {
    state.data = {
      x: typed(model.get("x"), Float32Array),
      lo: typed(model.get("planned_lo"), Float32Array),
      hi: typed(model.get("planned_hi"), Float32Array),
      cmd: typed(model.get("commanded"), Float32Array),
      line: typed(model.get("line"), Int32Array),
      move: typed(model.get("move"), Int32Array),
    };
  }

  function scales() {
    const [x0, x1] = model.get("range");
    const h = model.get("height");
    const ymax = model.get("ymax") || 1;
    const w = state.width;
    return {
      sx: (x) => pad.left + ((x - x0) / (x1 - x0 || 1)) * (w - pad.left - pad.right),
      sy: (y) => h - pad.bottom - (y / ymax) * (h - pad.top - pad.bottom),
      x0, x1, ymax, w, h,
    };
  }

  function draw() {
    state.pending = false;
    const ratio = window.devicePixelRatio || 1;
    const h = model.get("height");
    canvas.width = Math.round(state.width * ratio);
    canvas.height = Math.round(h * ratio);
    ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, state.width, h);
    const d = state.data;
    const s = scales();
    // axes and grid
    ctx.strokeStyle = "#e5e5e5";
    ctx.fillStyle = "#333";
    ctx.lineWidth = 1;
    ctx.font = "11px sans-serif";
    for (const v of ticks(0, s.ymax, 5)) {
      const y = s.sy(v);
      ctx.beginPath(); ctx.moveTo(pad.left, y); ctx.lineTo(s.w - pad.right, y); ctx.stroke();
      ctx.textAlign = "right"; ctx.fillText(String(+v.toPrecision(4)), pad.left - 4, y + 4);
    }
    for (const v of ticks(s.x0, s.x1, 8)) {
      const x = s.sx(v);
      ctx.beginPath(); ctx.moveTo(x, pad.top); ctx.lineTo(x, h - pad.bottom); ctx.stroke();
      ctx.textAlign = "center"; ctx.fillText(String(+v.toPrecision(6)), x, h - pad.bottom + 14);
    }
    ctx.textAlign = "center";
    ctx.fillText(model.get("x_label"), pad.left + (s.w - pad.left - pad.right) / 2, h - 4);
    ctx.save();
    ctx.translate(12, pad.top + (h - pad.top - pad.bottom) / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.fillText("speed (mm/s)", 0, 0);
    ctx.restore();
    ctx.save();
    ctx.beginPath();
    ctx.rect(pad.left, pad.top, s.w - pad.left - pad.right, h - pad.top - pad.bottom);
    ctx.clip();
    const n = d.x.length;
    const raw = model.get("mode") === "raw";
    // commanded feed: a step line
    ctx.strokeStyle = COLORS.commanded;
    ctx.setLineDash([4, 3]);
    ctx.beginPath();
    for (let i = 0; i < n; i++) {
      const x = s.sx(d.x[i]), y = s.sy(d.cmd[i]);
      if (i === 0) ctx.moveTo(x, y); else ctx.lineTo(x, y);
    }
    ctx.stroke();
    ctx.setLineDash([]);
    if (raw) { // each move's corners: accelerate, cruise, decelerate
      const phases = [COLORS.accel, COLORS.cruise, COLORS.decel, "#bbb"];
      const corners = model.get("corners");
      ctx.lineWidth = 1.5;
      for (let i = 0; i + 1 < n; i++) {
        ctx.strokeStyle = corners === 4 ? phases[i % 4] : COLORS.planned;
        ctx.beginPath();
        ctx.moveTo(s.sx(d.x[i]), s.sy(d.hi[i]));
        ctx.lineTo(s.sx(d.x[i + 1]), s.sy(d.hi[i + 1]));
        ctx.stroke();
      }
    } else { // per-bin envelope: a vertical bar from the lowest to the highest speed
      ctx.strokeStyle = COLORS.planned;
      ctx.beginPath();
      for (let i = 0; i < n; i++) {
        const x = s.sx(d.x[i]);
        ctx.moveTo(x, s.sy(d.lo[i]));
        ctx.lineTo(x, s.sy(d.hi[i]) - 0.5);
      }
      ctx.stroke();
    }
    const picked = model.get("picked");
    if (picked && picked.length === 3) {
      ctx.strokeStyle = "#e4002b";
      const x = s.sx(picked[2]);
      ctx.beginPath(); ctx.moveTo(x, pad.top); ctx.lineTo(x, h - pad.bottom); ctx.stroke();
    }
    ctx.restore();
    // legend
    const items = raw && model.get("corners") === 4
      ? [["accelerating", COLORS.accel], ["cruising", COLORS.cruise], ["decelerating", COLORS.decel], ["commanded", COLORS.commanded]]
      : [["planned (min-max per pixel)", COLORS.planned], ["commanded", COLORS.commanded]];
    let lx = pad.left;
    ctx.textAlign = "left";
    for (const [name, color] of items) {
      ctx.fillStyle = color; ctx.fillRect(lx, 8, 14, 4);
      ctx.fillStyle = "#333"; ctx.fillText(name, lx + 18, 14);
      lx += ctx.measureText(name).width + 34;
    }
    state.frame += 1;
    status.textContent = `${model.get("title")} · ${raw ? "every corner" : "min/max per bin"} · ${n} points`;
    status.dataset.frame = String(state.frame);
    status.dataset.points = String(n);
  }

  function schedule() {
    if (!state.pending) { state.pending = true; requestAnimationFrame(draw); }
  }

  function nearest(event) {
    const d = state.data;
    if (!d || d.x.length === 0) return -1;
    const rect = canvas.getBoundingClientRect();
    const s = scales();
    const x = s.x0 + ((event.clientX - rect.left - pad.left) / (s.w - pad.left - pad.right)) * (s.x1 - s.x0);
    let lo = 0, hi = d.x.length - 1;
    while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (d.x[mid] < x) lo = mid; else hi = mid; }
    return Math.abs(d.x[lo] - x) <= Math.abs(d.x[hi] - x) ? lo : hi;
  }

  canvas.addEventListener("mousemove", (e) => {
    const i = nearest(e);
    if (i < 0) return;
    const d = state.data;
    const rect = canvas.getBoundingClientRect();
    tip.style.display = "block";
    tip.style.left = Math.min(e.clientX - rect.left + 12, state.width - 220) + "px";
    tip.style.top = Math.max(e.clientY - rect.top - 28, 0) + "px";
    tip.textContent = `${model.get("x_label").split(" ")[0]} ${(+d.x[i]).toPrecision(6)} · planned ` +
      `${d.hi[i].toFixed(1)} mm/s · commanded ${d.cmd[i].toFixed(1)} mm/s · move ${d.move[i]} · line ${d.line[i]}`;
  });
  canvas.addEventListener("mouseleave", () => { tip.style.display = "none"; });
  canvas.addEventListener("click", (e) => {
    const i = nearest(e);
    if (i < 0) return;
    const d = state.data;
    model.set("picked", [d.move[i], d.line[i], d.x[i]]);
    model.save_changes();
  });

  const resize = new ResizeObserver((entries) => {
    const width = Math.round(entries[entries.length - 1].contentRect.width);
    if (width !== state.width) { state.width = width; schedule(); }
  });
  resize.observe(box);
  const setHeight = () => { box.style.height = model.get("height") + "px"; schedule(); };
  const onData = () => { load(); schedule(); };
  model.on("change:x change:planned_lo change:planned_hi change:commanded", onData);
  model.on("change:range change:ymax change:mode change:picked change:title", schedule);
  model.on("change:height", setHeight);
  load();
  setHeight();
  return () => {
    resize.disconnect();
    model.off("change:x change:planned_lo change:planned_hi change:commanded", onData);
    model.off("change:range change:ymax change:mode change:picked change:title", schedule);
    model.off("change:height", setHeight);
  };
}

export default { render };
