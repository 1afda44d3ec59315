// gcodekit LayerViewer front end: the toolpath's segments drawn with WebGL.
//
// The segments arrive once as binary buffers (positions, values, kinds, each
// one's move and the group offsets); a layer or move step only changes which
// contiguous range of them is drawn, so a step costs one draw call, not a new
// mesh.  A large program arrives as an overview (chords through every
// stride-th point of each run, stride > 1): the layers below the top one are
// drawn from it, and the top layer from its own segments, asked of the kernel
// when it is first shown and kept (a few dozen layers at most).
// The camera is orthographic with Z up, as in gcodekit/widgets/picture.py:
// azimuth turns about Z, elevation lifts the eye from the XY plane.

const VERTEX = `
attribute vec3 a_pos;
attribute float a_val;
attribute float a_kind;
uniform mat4 u_mvp;
uniform float u_vmin, u_vmax, u_cat, u_ncat, u_point;
varying float v_t;
varying float v_kind;
void main() {
  gl_Position = u_mvp * vec4(a_pos, 1.0);
  gl_PointSize = u_point;
  v_kind = a_kind;
  if (u_cat > 0.5) {
    v_t = (a_val + 0.5) / u_ncat;
  } else {
    float span = max(u_vmax - u_vmin, 1e-12);
    v_t = clamp((a_val - u_vmin) / span, 0.0, 1.0) * (255.0 / 256.0) + 0.5 / 256.0;
  }
}`;

const FRAGMENT = `
precision mediump float;
uniform sampler2D u_cmap;
uniform float u_travel, u_solid;
uniform vec4 u_color;
varying float v_t;
varying float v_kind;
void main() {
  if (u_solid > 0.5) { gl_FragColor = u_color; return; }
  if (v_kind > 0.5) {
    if (u_travel < 0.5) discard;
    gl_FragColor = vec4(0.604, 0.604, 0.604, 1.0); // TRAVEL_COLOR, #9a9a9a (gcodekit/view/coloring.py)
    return;
  }
  gl_FragColor = vec4(texture2D(u_cmap, vec2(v_t, 0.5)).rgb, 1.0);
}`;

function typed(view, Type) {
  // a copy, so the array starts on an aligned offset whatever buffer it came in
  if (!view || view.byteLength === 0) return new Type(0);
  return new Type(view.buffer.slice(view.byteOffset, view.byteOffset + view.byteLength));
}

function compile(gl, type, source) {
  const shader = gl.createShader(type);
  gl.shaderSource(shader, source);
  gl.compileShader(shader);
  if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(shader));
  return shader;
}

function cameraAxes(cam) {
  const az = (cam.azimuth * Math.PI) / 180;
  const el = (Math.max(-89.9, Math.min(89.9, cam.elevation)) * Math.PI) / 180;
  const eye = [Math.cos(el) * Math.cos(az), Math.cos(el) * Math.sin(az), Math.sin(el)];
  const right = [-Math.sin(az), Math.cos(az), 0];
  const up = [eye[1] * right[2] - eye[2] * right[1], eye[2] * right[0] - eye[0] * right[2],
    eye[0] * right[1] - eye[1] * right[0]];
  return { right, up, eye };
}

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];

function matrix(cam, radius, aspect) {
  const { right, up, eye } = cameraAxes(cam);
  const half = radius / Math.max(cam.zoom, 1e-6);
  const sx = half * aspect, sy = half, sz = radius * 50;
  const t = cam.target;
  const m = new Float32Array(16); // column-major
  for (let i = 0; i < 3; i++) {
    m[i * 4 + 0] = right[i] / sx;
    m[i * 4 + 1] = up[i] / sy;
    m[i * 4 + 2] = -eye[i] / sz;
  }
  m[12] = -dot(t, right) / sx;
  m[13] = -dot(t, up) / sy;
  m[14] = dot(t, eye) / sz;
  m[15] = 1;
  return m;
}

function softwareRenderer() {
  // WebGL drawn on the CPU (no GPU): antialiasing there costs more than the drawing itself
  const probe = document.createElement("canvas").getContext("webgl");
  if (!probe) return true;
  const info = probe.getExtension("WEBGL_debug_renderer_info");
  const name = info ? String(probe.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
  const lose = probe.getExtension("WEBGL_lose_context");
  if (lose) lose.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}

function render({ model, el }) {
  el.classList.add("gcodekit-viewer");
  const box = document.createElement("div");
  box.style.cssText = "position:relative;width:100%;min-width:0;font:12px sans-serif;user-select:none;" +
    "border:1px solid #ddd;box-sizing:border-box";
  const canvas = document.createElement("canvas");
  canvas.tabIndex = 0;
  canvas.title = "drag: rotate · shift-drag: pan · wheel: zoom · double-click: reset · " +
    "arrows: step moves (left/right) and layers (up/down) · Home/End";
  // the canvas is laid over its box: its pixel size must not feed back into the page's layout
  canvas.style.cssText = "position:absolute;inset:0;width:100%;height:100%;outline:none;background:#fff";
  const legend = document.createElement("div");
  legend.className = "gk-legend";
  legend.style.cssText = "position:absolute;top:6px;right:8px;background:rgba(255,255,255,0.85);padding:4px 6px;" +
    "max-width:40%;pointer-events:none";
  const status = document.createElement("div");
  status.className = "gk-status";
  status.style.cssText = "position:absolute;left:8px;bottom:6px;color:#333;background:rgba(255,255,255,0.8);" +
    "padding:1px 4px;pointer-events:none";
  box.append(canvas, legend, status);
  el.append(box);

  const software = softwareRenderer();
  const attributes = { antialias: !software, preserveDrawingBuffer: true };
  const gl = canvas.getContext("webgl2", attributes) || canvas.getContext("webgl", attributes);
  if (!gl) {
    status.textContent = "WebGL is not available in this browser: the picture below the controls is the last one drawn in Python.";
    return () => {};
  }
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl, gl.VERTEX_SHADER, VERTEX));
  gl.attachShader(program, compile(gl, gl.FRAGMENT_SHADER, FRAGMENT));
  gl.linkProgram(program);
  gl.useProgram(program);
  const loc = (name) => gl.getUniformLocation(program, name);
  const u = {};
  for (const name of ["u_mvp", "u_vmin", "u_vmax", "u_cat", "u_ncat", "u_point", "u_cmap", "u_travel", "u_solid", "u_color"]) {
    u[name] = loc(name);
  }
  const buffers = { pos: gl.createBuffer(), val: gl.createBuffer(), kind: gl.createBuffer() };
  // layers' own segments, by group: their buffers, values, kinds and each move's first segment
  const details = new Map();
  const asked = new Set();
  const KEEP = 32;
  const texture = gl.createTexture();
  // On a software renderer every segment costs: pictures of the range drawn so far are kept at
  // checkpoints, so a step redraws at most one checkpoint's worth of segments plus the top layer.
  const cache = software && typeof WebGL2RenderingContext !== "undefined" && gl instanceof WebGL2RenderingContext
    ? { key: "", work: null, points: [], width: 0, height: 0 } : null;
  const state = { nSeg: 0, values: new Float32Array(0), kinds: new Uint8Array(0), segMove: new Int32Array(0),
    groupSeg: new Int32Array(1), groupMove: new Int32Array(1), moveLimit: null, frame: 0, pending: false, ncat: 0,
    width: 0, drawn: "", version: 0 }; // width 0: not laid out yet (the ResizeObserver tells)

  function attribute(name, buffer, size) {
    const index = gl.getAttribLocation(program, name);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
    gl.enableVertexAttribArray(index);
    gl.vertexAttribPointer(index, size, gl.FLOAT, false, 0, 0);
  }

  function use(set) { // draw from the overview's buffers or a layer's own
    attribute("a_pos", set.pos, 3);
    attribute("a_kind", set.kind, 1);
    attribute("a_val", set.val, 1);
  }

  function dropDetails() {
    for (const d of details.values()) { gl.deleteBuffer(d.pos); gl.deleteBuffer(d.kind); gl.deleteBuffer(d.val); }
    details.clear();
    asked.clear();
  }

  function ask(group) {
    const groups = state.groupMove.length - 1;
    if (model.get("stride") === 1 || group < 0 || group >= groups || details.has(group) || asked.has(group)) return;
    asked.add(group);
    model.send({ detail: group });
  }

  function onDetail(msg, views) {
    if (!msg || msg.detail === undefined || msg.version !== model.get("color_version")) return;
    asked.delete(msg.detail);
    const make = (data) => { const b = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW); return b; };
    const values = typed(views[2], Float32Array), kinds = typed(views[1], Uint8Array);
    details.set(msg.detail, { pos: make(typed(views[0], Float32Array)), kind: make(perVertex(kinds)),
      val: make(perVertex(values)), values, kinds, moveSeg: typed(views[3], Int32Array) });
    while (details.size > KEEP) { // the layer shown longest ago goes
      const [group, d] = details.entries().next().value;
      gl.deleteBuffer(d.pos); gl.deleteBuffer(d.kind); gl.deleteBuffer(d.val);
      details.delete(group);
    }
    schedule();
  }

  function upper(array, lo, hi, value) { // first index in [lo, hi) whose value exceeds value
    while (lo < hi) { const mid = (lo + hi) >> 1; if (array[mid] <= value) lo = mid + 1; else hi = mid; }
    return lo;
  }

  function perVertex(perSegment) {
    const out = new Float32Array(perSegment.length * 2);
    for (let i = 0; i < perSegment.length; i++) out[2 * i] = out[2 * i + 1] = perSegment[i];
    return out;
  }

  function loadGeometry() {
    const pos = typed(model.get("positions"), Float32Array);
    state.nSeg = pos.length / 6;
    state.kinds = typed(model.get("kinds"), Uint8Array);
    state.segMove = typed(model.get("seg_move"), Int32Array);
    state.groupSeg = typed(model.get("group_seg"), Int32Array);
    state.groupMove = typed(model.get("group_move"), Int32Array);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.pos);
    gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.kind);
    gl.bufferData(gl.ARRAY_BUFFER, perVertex(state.kinds), gl.STATIC_DRAW);
    state.version += 1;
  }

  function loadColors() {
    state.values = typed(model.get("values"), Float32Array);
    gl.bindBuffer(gl.ARRAY_BUFFER, buffers.val);
    gl.bufferData(gl.ARRAY_BUFFER, perVertex(state.values), gl.STATIC_DRAW);
    dropDetails(); // the layers' own values are another colouring's
    const table = typed(model.get("palette"), Uint8Array);
    const n = Math.max(table.length / 3, 1);
    const rgba = new Uint8Array(n * 4);
    for (let i = 0; i < n; i++) {
      rgba[4 * i] = table[3 * i]; rgba[4 * i + 1] = table[3 * i + 1]; rgba[4 * i + 2] = table[3 * i + 2];
      rgba[4 * i + 3] = 255;
    }
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, n, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, rgba);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    state.ncat = (model.get("categories") || []).length;
    state.palette = table;
    state.version += 1; // a new colouring: the same range must be drawn again
  }

  function span() {
    const groups = state.groupMove.length - 1;
    if (groups < 1) return null;
    let [lo, hi] = model.get("layers");
    lo = Math.max(0, Math.min(lo, groups - 1));
    hi = Math.max(lo, Math.min(hi, groups - 1));
    const gm = state.groupMove, gs = state.groupSeg;
    const count = gm[hi + 1] - gm[hi];
    const shown = state.moveLimit === null ? count : Math.min(Math.max(state.moveLimit, 0) + 1, count);
    const current = count > 0 ? gm[hi] + shown - 1 : -1;
    // the chords of the top group up to the current move (those that start by then)
    const cut = upper(state.segMove, gs[hi], gs[hi + 1], current);
    const detail = model.get("stride") === 1 ? null : details.get(hi) || null;
    if (detail) { details.delete(hi); details.set(hi, detail); } // kept the longest: the layers shown last
    return { lo, hi, a: gs[lo], base: gs[hi], b: cut, current, shown, count, detail };
  }

  // the top group: [values, kinds, first, end] of what is drawn of it
  function top(s) {
    if (s.detail) return [s.detail.values, s.detail.kinds, 0, s.detail.moveSeg[s.shown]];
    return [state.values, state.kinds, s.base, s.b];
  }

  function hex(r, g, b) {
    return "#" + [r, g, b].map((v) => v.toString(16).padStart(2, "0")).join("");
  }

  // every text here comes from the program (a slicer's ;TYPE: names) or the kernel: it is set as
  // text, never parsed as HTML
  function element(tag, css, text) {
    const node = document.createElement(tag);
    if (css) node.style.cssText = css;
    if (text !== undefined) node.textContent = text;
    return node;
  }

  function drawLegend(s, vmin, vmax, present) {
    const nodes = [element("div", "font-weight:600;margin-bottom:2px", model.get("title"))];
    const cats = model.get("categories") || [];
    const p = state.palette;
    if (cats.length) {
      for (let k = 0; k < cats.length; k++) {
        if (!present[k]) continue;
        const j = (k % (p.length / 3)) * 3;
        const swatch = element("span", "display:inline-block;width:10px;height:10px;margin-right:4px");
        swatch.style.background = hex(p[j], p[j + 1], p[j + 2]);
        const row = element("div");
        row.className = "gk-category";
        row.append(swatch, element("span", "", String(cats[k])));
        nodes.push(row);
      }
      legend.replaceChildren(...nodes);
      return;
    }
    if (vmin === vmax) {
      // one value on screen: a swatch that says so (the shader draws a zero span at the scale's low end)
      const swatch = element("span", "display:inline-block;width:10px;height:10px;margin-right:4px");
      swatch.style.background = hex(p[0], p[1], p[2]);
      const row = element("div");
      row.className = "gk-one-value";
      row.append(swatch, element("span", "", `every move: ${Number(vmin.toPrecision(6))}`));
      nodes.push(row);
      legend.replaceChildren(...nodes);
      return;
    }
    const stops = [];
    for (let i = 0; i <= 8; i++) {
      const j = Math.round((i / 8) * 255) * 3;
      stops.push(hex(p[j], p[j + 1], p[j + 2]));
    }
    const fmt = (v) => (Math.abs(v) >= 100 ? v.toFixed(0) : Math.abs(v) >= 1 ? v.toFixed(1) : v.toPrecision(2));
    const bar = element("div", "width:12px;height:120px");
    bar.style.background = `linear-gradient(to top,${stops.join(",")})`;
    const ticks = element("div", "display:flex;flex-direction:column;justify-content:space-between");
    ticks.append(element("span", "", fmt(vmax)), element("span", "", fmt((vmin + vmax) / 2)),
      element("span", "", fmt(vmin)));
    const scale = element("div", "display:flex;align-items:stretch;gap:4px");
    scale.append(bar, ticks);
    nodes.push(scale);
    legend.replaceChildren(...nodes);
  }

  function draw() {
    state.pending = false;
    // before the first layout the width is unknown: a picture drawn at a guessed width was drawn again at
    // the real one a frame later (1-2 s each for a large program on a software renderer)
    if (state.width === 0) return;
    const s = span();
    const camera = model.get("camera");
    const ratio = window.devicePixelRatio || 1;
    // the size comes from the ResizeObserver: reading it here would force a layout of the whole page
    const width = Math.round(Math.max(state.width, 50) * ratio), height = Math.round(model.get("height") * ratio);
    const key = JSON.stringify([s && [s.lo, s.hi, s.a, s.b, s.shown, s.detail !== null], camera, width, height,
      model.get("show_travel"), state.version]);
    if (key === state.drawn) return; // the same picture (a control echoed back by the kernel)
    state.drawn = key;
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
    }
    gl.viewport(0, 0, canvas.width, canvas.height);
    gl.clearColor(1, 1, 1, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.depthFunc(gl.LEQUAL);
    if (!s) return;
    // the colour scale spans the work shown (the legend says what is on screen)
    let vmin = Infinity, vmax = -Infinity;
    const cats = state.ncat;
    const present = new Uint8Array(Math.max(cats, 1));
    const [tv, tk, t0, t1] = top(s);
    for (const [v, k, i0, i1] of [[state.values, state.kinds, s.a, s.base], [tv, tk, t0, t1]]) {
      for (let i = i0; i < i1; i++) {
        if (k[i] !== 0) continue;
        const x = v[i];
        if (cats) present[x] = 1;
        else if (Number.isFinite(x)) { if (x < vmin) vmin = x; if (x > vmax) vmax = x; }
      }
    }
    if (!(vmin <= vmax)) { vmin = 0; vmax = 1; }
    gl.uniformMatrix4fv(u.u_mvp, false, matrix(camera, model.get("radius"), canvas.width / canvas.height));
    gl.uniform1f(u.u_vmin, vmin);
    gl.uniform1f(u.u_vmax, vmax);
    gl.uniform1f(u.u_cat, cats ? 1 : 0);
    gl.uniform1f(u.u_ncat, Math.max(cats, 1));
    gl.uniform1f(u.u_travel, model.get("show_travel") ? 1 : 0);
    gl.uniform1f(u.u_solid, 0);
    gl.uniform1f(u.u_point, 9 * ratio);
    gl.uniform1i(u.u_cmap, 0);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, texture);
    use(buffers);
    if (cache) {
      drawCached(s, JSON.stringify([s.lo, camera, canvas.width, canvas.height, model.get("show_travel"), state.version,
        vmin, vmax]));
    } else if (s.base > s.a) {
      gl.drawArrays(gl.LINES, 2 * s.a, 2 * (s.base - s.a));
    }
    drawTop(s);
    if (cache) copy(cache.work.fb, null, gl.COLOR_BUFFER_BIT);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    // the current move in red, its end as a dot (from the overview: when a chord of its own starts there)
    let m0 = -1, m1 = -1;
    if (s.detail && s.current >= 0) {
      use(s.detail);
      m0 = s.detail.moveSeg[s.shown - 1]; m1 = s.detail.moveSeg[s.shown];
    } else if (s.current >= 0 && s.b > s.base && state.segMove[s.b - 1] === s.current) {
      m0 = upper(state.segMove, s.base, s.b, s.current - 1); m1 = s.b;
    }
    if (m1 > m0 && m0 >= 0) {
      gl.uniform1f(u.u_solid, 1);
      gl.uniform4f(u.u_color, 0.89, 0.0, 0.17, 1.0);
      gl.disable(gl.DEPTH_TEST);
      gl.drawArrays(gl.LINES, 2 * m0, 2 * (m1 - m0));
      gl.drawArrays(gl.POINTS, 2 * m1 - 1, 1);
    }
    drawLegend(s, vmin, vmax, present);
    const labels = model.get("group_labels");
    const groups = s.lo === s.hi ? labels[s.lo] : `${labels[s.lo]} to ${labels[s.hi]}`;
    const full = model.get("stride") === 1 || s.detail !== null;
    const drawn = s.base - s.a + t1 - t0;
    state.frame += 1;
    status.textContent = `${groups} · move ${s.shown} of ${s.count} · ${drawn} segments` +
      (model.get("stride") === 1 ? "" : full ? " (layers below: overview)" : " (overview)");
    status.dataset.detail = full ? "full" : "overview";
    status.dataset.frame = String(state.frame);
    status.dataset.segments = String(drawn);
    if (!full) ask(s.hi);
    else { ask(s.hi - 1); ask(s.hi + 1); } // the next steps' layers, while the view is idle
  }

  function drawTop(s) { // into the framebuffer bound: the top group, its own segments or the overview's chords
    if (s.detail) {
      const n = s.detail.moveSeg[s.shown];
      use(s.detail);
      if (n > 0) gl.drawArrays(gl.LINES, 0, 2 * n);
      use(buffers);
    } else if (s.b > s.base) {
      gl.drawArrays(gl.LINES, 2 * s.base, 2 * (s.b - s.base));
    }
  }

  function target(w, h) {
    // a framebuffer with its own colour and depth: the picture up to a checkpoint, or the work picture
    const fb = gl.createFramebuffer(), color = gl.createRenderbuffer(), depth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, color);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA8, w, h);
    gl.bindRenderbuffer(gl.RENDERBUFFER, depth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, w, h);
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, color);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, depth);
    return { fb, color, depth };
  }

  function release(t) {
    if (!t) return;
    gl.deleteFramebuffer(t.fb); gl.deleteRenderbuffer(t.color); gl.deleteRenderbuffer(t.depth);
  }

  function copy(from, to, bits) {
    gl.bindFramebuffer(gl.READ_FRAMEBUFFER, from);
    gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, to);
    gl.blitFramebuffer(0, 0, cache.width, cache.height, 0, 0, cache.width, cache.height, bits, gl.NEAREST);
  }

  function drawCached(s, key) {
    const w = canvas.width, h = canvas.height;
    if (key !== cache.key || w !== cache.width || h !== cache.height) { // another picture: start again
      cache.points.forEach(release);
      release(cache.work);
      Object.assign(cache, { key, width: w, height: h, points: [], work: target(w, h) });
    }
    // at most 24 checkpoints (memory: two buffers of the canvas's size each), 2000 segments apart or more
    const step = Math.max(2000, Math.ceil(state.nSeg / 24));
    const base = s.base; // where the top group starts
    const both = gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT;
    let j = Math.min(Math.floor((base - s.a) / step), cache.points.length) - 1;
    while (j >= 0 && !cache.points[j]) j--;
    let pos = s.a;
    if (j >= 0) {
      copy(cache.points[j].fb, cache.work.fb, both);
      pos = s.a + (j + 1) * step;
    } else {
      gl.bindFramebuffer(gl.FRAMEBUFFER, cache.work.fb);
      gl.clear(both);
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, cache.work.fb);
    while (pos < base) {
      const k = Math.floor((pos - s.a) / step);
      const stop = Math.min(base, s.a + (k + 1) * step);
      gl.drawArrays(gl.LINES, 2 * pos, 2 * (stop - pos));
      if (stop === s.a + (k + 1) * step) { // a checkpoint reached: keep its picture
        cache.points[k] = cache.points[k] || target(w, h);
        copy(cache.work.fb, cache.points[k].fb, both);
        gl.bindFramebuffer(gl.FRAMEBUFFER, cache.work.fb);
      }
      pos = stop;
    }
    gl.bindFramebuffer(gl.FRAMEBUFFER, cache.work.fb); // the top group is drawn over it by the caller
  }

  function schedule() {
    if (!state.pending) { state.pending = true; requestAnimationFrame(draw); }
  }

  // -- camera: drag to rotate, shift-drag to pan, wheel to zoom ------------------
  let drag = null;
  function sendCamera() {
    model.set("camera", { ...model.get("camera") });
    model.save_changes();
  }
  canvas.addEventListener("pointerdown", (e) => {
    drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
    canvas.setPointerCapture(e.pointerId);
    canvas.focus();
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    const cam = { ...model.get("camera") };
    if (drag.pan) {
      const { right, up } = cameraAxes(cam);
      const perPixel = (2 * model.get("radius")) / Math.max(cam.zoom, 1e-6) / canvas.clientHeight;
      cam.target = cam.target.map((t, i) => t - (dx * right[i] - dy * up[i]) * perPixel);
    } else {
      cam.azimuth -= dx * 0.4;
      cam.elevation = Math.max(-89, Math.min(89, cam.elevation + dy * 0.4));
    }
    model.set("camera", cam);
  });
  canvas.addEventListener("pointerup", () => { if (drag) { drag = null; sendCamera(); } });
  canvas.addEventListener("contextmenu", (e) => e.preventDefault());
  let wheelTimer = null;
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    const cam = { ...model.get("camera") };
    cam.zoom = Math.max(0.05, Math.min(200, cam.zoom * Math.exp(-e.deltaY * 0.0015)));
    model.set("camera", cam);
    clearTimeout(wheelTimer);
    wheelTimer = setTimeout(sendCamera, 200);
  }, { passive: false });
  canvas.addEventListener("dblclick", () => {
    model.set("camera", { azimuth: -60, elevation: 30, zoom: 1, target: [0, 0, 0] });
    sendCamera();
  });

  // -- keys: left/right step the move, up/down the layer, Home/End -----------------
  canvas.addEventListener("keydown", (e) => {
    const s = span();
    if (!s) return;
    const groups = state.groupMove.length - 1;
    let [lo, hi] = model.get("layers");
    let move = s.shown - 1;
    if (e.key === "ArrowRight") move = Math.min(move + 1, s.count - 1);
    else if (e.key === "ArrowLeft") move = Math.max(move - 1, 0);
    else if (e.key === "Home") move = 0;
    else if (e.key === "End") move = s.count - 1;
    else if (e.key === "ArrowUp" || e.key === "ArrowDown") {
      const step = e.key === "ArrowUp" ? 1 : -1;
      const single = lo === hi;
      hi = Math.max(0, Math.min(groups - 1, hi + step));
      lo = single ? hi : Math.min(lo, hi);
      model.set("layers", [lo, hi]);
      model.save_changes();
      e.preventDefault();
      return;
    } else return;
    e.preventDefault();
    model.set("top_move", [hi, move]);
    model.save_changes();
  });

  const onGeometry = () => { loadGeometry(); schedule(); };
  const onColors = () => { loadColors(); schedule(); };
  const onLayers = () => { state.moveLimit = null; schedule(); };
  // a move counts within the top group it was chosen in: one meant for another group
  // (the kernel answering an older step) is not applied
  const onMove = () => {
    const [group, move] = model.get("top_move");
    if (group === model.get("layers")[1]) { state.moveLimit = move; schedule(); }
  };
  model.on("change:positions", onGeometry);
  model.on("msg:custom", onDetail);
  model.on("change:values change:palette change:categories change:title", onColors);
  model.on("change:layers", onLayers);
  model.on("change:top_move", onMove);
  model.on("change:show_travel change:camera change:height", schedule);
  const resize = new ResizeObserver((entries) => {
    const width = Math.round(entries[entries.length - 1].contentRect.width);
    if (width !== state.width) { state.width = width; schedule(); }
  });
  resize.observe(box);
  const setHeight = () => { box.style.height = model.get("height") + "px"; };
  model.on("change:height", setHeight);
  setHeight();
  loadGeometry();
  loadColors();
  onMove();
  schedule();
  return () => {
    if (cache) { cache.points.forEach(release); release(cache.work); }
    resize.disconnect();
    model.off("change:positions", onGeometry);
    model.off("msg:custom", onDetail);
    dropDetails();
    model.off("change:values change:palette change:categories change:title", onColors);
    model.off("change:layers", onLayers);
    model.off("change:top_move", onMove);
    model.off("change:show_travel change:camera change:height", schedule);
    model.off("change:height", setHeight);
  };
}

export default { render };
