// The report page's stylesheet and its WebGL viewer, written for isohex and kept here as
// raw strings so that report.html needs nothing from the network or the build machine.
//
// The viewer (WebGL 1, so that software renderers such as SwiftShader run it) draws the
// surface of the set of kept cells: a quad is drawn when exactly one of its two cells is
// kept, facing away from that cell and coloured by that cell's scaled Jacobian. A cell is
// kept when its centroid lies on the chosen side of the cut plane and its scaled Jacobian is
// at most the filter value. Data layout: see report_viewer_data.cpp.
#include "isohex/quality/report_detail.hpp"

namespace isohex::report_detail {

const char* const kReportCss = R"css(
body { font-family: system-ui, sans-serif; margin: 0 auto; max-width: 1180px; padding: 12px 16px; color: #222; }
h1 { font-size: 22px; margin: 4px 0 8px; }
h2 { font-size: 17px; margin: 22px 0 8px; border-bottom: 1px solid #ddd; padding-bottom: 3px; }
.cards { display: flex; gap: 10px; flex-wrap: wrap; margin-bottom: 10px; }
.card { border: 1px solid #ddd; border-radius: 6px; padding: 6px 12px; min-width: 120px; }
.card b { display: block; font-size: 18px; }
.card span { color: #666; font-size: 12px; }
.bad { color: #cc3311; }
.view { display: flex; gap: 14px; align-items: flex-start; flex-wrap: wrap; }
#viewer { border: 1px solid #ccc; border-radius: 4px; background: #f4f5f7; cursor: grab; touch-action: none;
          max-width: 100%; height: auto; }
.panel { width: 360px; font-size: 13px; }
.panel label { display: block; margin: 6px 0; }
.panel input[type=range] { width: 100%; }
#viewer-status { font-size: 12px; color: #555; margin-top: 4px; }
#viewer-status[data-state=error], #viewer-errors { color: #cc3311; }
table { border-collapse: collapse; font-size: 13px; }
th, td { border: 1px solid #ddd; padding: 3px 8px; text-align: right; vertical-align: top; }
th { background: #f3f3f3; }
td.l, th.l { text-align: left; }
.figures { display: grid; grid-template-columns: repeat(auto-fill, minmax(540px, 1fr)); gap: 12px; }
figure { margin: 0; }
figure svg { width: 100%; height: auto; border: 1px solid #eee; }
figcaption { font-size: 12px; color: #555; }
.note { font-size: 12px; color: #666; }
)css";

const char* const kViewerHtml = R"html(
<div class="view">
 <div>
  <canvas id="viewer" width="760" height="560" aria-label="3D view of the mesh coloured by scaled Jacobian"></canvas>
  <div id="viewer-status" data-state="loading">loading the mesh…</div>
  <ul id="viewer-errors" hidden></ul>
 </div>
 <div class="panel">
  <label>cut across <select id="cut-axis"><option value="0">x</option><option value="1">y</option><option value="2">z</option></select>
   <input type="checkbox" id="cut-flip"> keep the other side</label>
  <label>cut position <span id="cut-value"></span><input type="range" id="cut-pos" min="0" max="1000" value="550"></label>
  <label>show hexes with scaled Jacobian ≤ <span id="sj-value"></span><input type="range" id="sj-max" min="-100" max="100" value="100"></label>
  <label><input type="checkbox" id="show-edges" checked> hex edges</label>
  <button id="reset-view" type="button">reset view</button>
  <p><canvas id="legend" width="340" height="46" aria-label="colour legend"></canvas></p>
  <p class="note">Drag to rotate, wheel to zoom, shift-drag (or right-drag) to pan. Colours: scaled Jacobian
   of the hex behind each face; magenta marks degenerate hexes. Faces seen from inside a hex (through a cut
   shell) are darker.</p>
  <p class="note" id="viewer-note"></p>
 </div>
</div>
)html";

const char* const kViewerJs = R"js(
(function () {
  'use strict';
  const statusEl = document.getElementById('viewer-status');
  const errorsEl = document.getElementById('viewer-errors');
  function fail(message) {
    statusEl.textContent = 'error: ' + message;
    statusEl.dataset.state = 'error';
    const li = document.createElement('li');
    li.textContent = message;
    errorsEl.appendChild(li);
    errorsEl.hidden = false;
  }
  window.addEventListener('error', (e) => fail(e.message + (e.filename ? ' (' + e.filename + ':' + e.lineno + ')' : '')));
  window.addEventListener('unhandledrejection', (e) => fail('unhandled rejection: ' + ((e.reason && e.reason.message) || e.reason)));

  // Colour map: dark to bright red below 0 (inverted), red-orange to orange up to 0.2
  // (questionable), then yellow, green and blue at 1 (the cube).
  const STOPS = [[-1, [0.45, 0.02, 0.05]], [0, [0.90, 0.12, 0.10]], [0, [0.93, 0.33, 0.10]], [0.2, [0.98, 0.60, 0.15]],
                 [0.5, [0.93, 0.85, 0.30]], [0.8, [0.30, 0.70, 0.32]], [1, [0.22, 0.47, 0.80]]];
  function sjColour(v) {
    if (!(Math.abs(v) < 1e29)) return [0.80, 0.20, 0.80];
    if (v <= STOPS[0][0]) return STOPS[0][1];
    for (let i = 1; i < STOPS.length; ++i) {
      const [b, cb] = STOPS[i];
      const [a, ca] = STOPS[i - 1];
      if (v < b || (v === b && i === STOPS.length - 1)) {
        const t = b > a ? (v - a) / (b - a) : 1;
        return [0, 1, 2].map((k) => ca[k] + t * (cb[k] - ca[k]));
      }
    }
    return STOPS[STOPS.length - 1][1];
  }

  function drawLegend() {
    const c = document.getElementById('legend');
    const g = c.getContext('2d');
    const x0 = 10, w = c.width - 20;
    for (let i = 0; i < w; ++i) {
      const rgb = sjColour(-1 + 2 * (i + 0.5) / w).map((k) => Math.round(255 * k));
      g.fillStyle = 'rgb(' + rgb.join(',') + ')';
      g.fillRect(x0 + i, 4, 1, 18);
    }
    g.fillStyle = '#222';
    g.font = '11px sans-serif';
    g.textAlign = 'center';
    for (const v of [-1, -0.5, 0, 0.2, 0.5, 1]) {
      const x = x0 + (v + 1) / 2 * w;
      g.fillRect(x, 22, 1, 4);
      g.fillText(String(v), Math.min(Math.max(x, 8), c.width - 8), 38);
    }
  }

  async function loadData() {
    const info = JSON.parse(document.getElementById('mesh-info').textContent);
    const text = document.getElementById('mesh-data').textContent.trim();
    const bin = atob(text);
    const packed = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; ++i) packed[i] = bin.charCodeAt(i);
    if (typeof DecompressionStream === 'undefined')
      throw new Error('this browser has no DecompressionStream (needs Chrome 80, Firefox 113, Safari 16.4 or later)');
    const stream = new Blob([packed]).stream().pipeThrough(new DecompressionStream('deflate'));
    const buf = await new Response(stream).arrayBuffer();
    if (buf.byteLength !== info.bytes) throw new Error('mesh data has ' + buf.byteLength + ' bytes, expected ' + info.bytes);
    let offset = 0;
    const take = (Type, n) => { const a = new Type(buf, offset, n); offset += 4 * n; return a; };
    return { info: info, points: take(Float32Array, 3 * info.points), quads: take(Uint32Array, 4 * info.quads),
             sides: take(Int32Array, 2 * info.quads), centroids: take(Float32Array, 3 * info.cells),
             sj: take(Float32Array, info.cells) };
  }

  // Column-major 4x4 matrices.
  function mul(a, b) {
    const r = new Float32Array(16);
    for (let c = 0; c < 4; ++c)
      for (let i = 0; i < 4; ++i) {
        let s = 0;
        for (let k = 0; k < 4; ++k) s += a[k * 4 + i] * b[c * 4 + k];
        r[c * 4 + i] = s;
      }
    return r;
  }
  function rotation(axis, angle) {
    const c = Math.cos(angle), s = Math.sin(angle), m = new Float32Array(16);
    m[15] = 1;
    const [i, j] = axis === 0 ? [1, 2] : axis === 1 ? [2, 0] : [0, 1];
    m[axis * 5] = 1;
    m[i * 4 + i] = c; m[j * 4 + j] = c; m[i * 4 + j] = s; m[j * 4 + i] = -s;
    return m;
  }
  function translation(x, y, z) {
    const m = new Float32Array(16);
    m[0] = m[5] = m[10] = m[15] = 1;
    m[12] = x; m[13] = y; m[14] = z;
    return m;
  }
  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2), m = new Float32Array(16);
    m[0] = f / aspect; m[5] = f; m[10] = (far + near) / (near - far); m[11] = -1; m[14] = 2 * far * near / (near - far);
    return m;
  }

  function compile(gl, vs, fs) {
    const prog = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const sh = gl.createShader(type);
      gl.shaderSource(sh, src);
      gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error('shader: ' + gl.getShaderInfoLog(sh));
      gl.attachShader(prog, sh);
    }
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error('shader link: ' + gl.getProgramInfoLog(prog));
    return prog;
  }

  const FACE_VS = 'attribute vec3 aPos; attribute vec3 aNrm; attribute vec3 aCol; uniform mat4 uMvp; uniform mat4 uView;' +
    'varying vec3 vCol; varying vec3 vNrm; void main() { gl_Position = uMvp * vec4(aPos, 1.0);' +
    ' vNrm = (uView * vec4(aNrm, 0.0)).xyz; vCol = aCol; }';
  // Head light; faces seen from behind (the inside of a cut shell) are dimmer.
  const FACE_FS = 'precision mediump float; varying vec3 vCol; varying vec3 vNrm; void main() {' +
    ' float d = abs(normalize(vNrm).z); float l = gl_FrontFacing ? 0.38 + 0.62 * d : 0.22 + 0.3 * d;' +
    ' gl_FragColor = vec4(vCol * l, 1.0); }';
  const LINE_VS = 'attribute vec3 aPos; uniform mat4 uMvp; void main() { gl_Position = uMvp * vec4(aPos, 1.0); }';
  const LINE_FS = 'precision mediump float; void main() { gl_FragColor = vec4(0.12, 0.12, 0.14, 1.0); }';

  function start(data) {
    const canvas = document.getElementById('viewer');
    const gl = canvas.getContext('webgl', { antialias: true, preserveDrawingBuffer: true });
    if (!gl) throw new Error('WebGL is not available in this browser');
    const faceProg = compile(gl, FACE_VS, FACE_FS), lineProg = compile(gl, LINE_VS, LINE_FS);
    const buffers = { pos: gl.createBuffer(), nrm: gl.createBuffer(), col: gl.createBuffer(), lines: gl.createBuffer() };
    const nc = data.info.cells, nq = data.info.quads;
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (let c = 0; c < nc; ++c)
      for (let k = 0; k < 3; ++k) {
        lo[k] = Math.min(lo[k], data.centroids[3 * c + k]);
        hi[k] = Math.max(hi[k], data.centroids[3 * c + k]);
      }
    const ui = {
      axis: document.getElementById('cut-axis'), pos: document.getElementById('cut-pos'),
      flip: document.getElementById('cut-flip'), sjMax: document.getElementById('sj-max'),
      edges: document.getElementById('show-edges'),
    };
    const kept = new Uint8Array(nc);
    let faceVertices = 0, lineVertices = 0, triangles = 0;

    function rebuild() {
      const axis = Number(ui.axis.value), frac = Number(ui.pos.value) / 1000, flip = ui.flip.checked;
      const sjMax = Number(ui.sjMax.value) / 100;
      const cut = flip ? hi[axis] - frac * (hi[axis] - lo[axis]) : lo[axis] + frac * (hi[axis] - lo[axis]);
      document.getElementById('cut-value').textContent = (100 * frac).toFixed(1) + ' %';
      document.getElementById('sj-value').textContent = sjMax.toFixed(2);
      const eps = 1e-6 * (hi[axis] - lo[axis] + 1e-30);
      for (let c = 0; c < nc; ++c) {
        const x = data.centroids[3 * c + axis], v = data.sj[c];
        const side = flip ? x >= cut - eps : x <= cut + eps;
        kept[c] = side && (sjMax >= 1 || !(Math.abs(v) < 1e29) || v <= sjMax) ? 1 : 0;
      }
      let nf = 0;
      for (let q = 0; q < nq; ++q) {
        const a = data.sides[2 * q], b = data.sides[2 * q + 1];
        if ((a >= 0 && kept[a] === 1) !== (b >= 0 && kept[b] === 1)) ++nf;
      }
      const pos = new Float32Array(nf * 18), nrm = new Float32Array(nf * 18), col = new Float32Array(nf * 18);
      const lines = new Float32Array(nf * 24);
      const P = data.points, corner = [0, 0, 0, 0];
      let f = 0;
      for (let q = 0; q < nq; ++q) {
        const a = data.sides[2 * q], b = data.sides[2 * q + 1];
        const ka = a >= 0 && kept[a] === 1, kb = b >= 0 && kept[b] === 1;
        if (ka === kb) continue;
        // Counter-clockwise seen from outside the kept cell: as stored for side 0, reversed for side 1.
        for (let i = 0; i < 4; ++i) corner[i] = data.quads[4 * q + (ka ? i : (4 - i) % 4)];
        const rgb = sjColour(data.sj[ka ? a : b]);
        const d1 = [0, 1, 2].map((k) => P[3 * corner[2] + k] - P[3 * corner[0] + k]);
        const d2 = [0, 1, 2].map((k) => P[3 * corner[3] + k] - P[3 * corner[1] + k]);
        const n = [d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2], d1[0] * d2[1] - d1[1] * d2[0]];
        const len = Math.hypot(n[0], n[1], n[2]) || 1;
        const tri = [0, 1, 2, 0, 2, 3];
        for (let t = 0; t < 6; ++t)
          for (let k = 0; k < 3; ++k) {
            pos[f * 18 + 3 * t + k] = P[3 * corner[tri[t]] + k];
            nrm[f * 18 + 3 * t + k] = n[k] / len;
            col[f * 18 + 3 * t + k] = rgb[k];
          }
        for (let e = 0; e < 4; ++e)
          for (let k = 0; k < 3; ++k) {
            lines[f * 24 + 6 * e + k] = P[3 * corner[e] + k];
            lines[f * 24 + 6 * e + 3 + k] = P[3 * corner[(e + 1) % 4] + k];
          }
        ++f;
      }
      for (const [buf, arr] of [[buffers.pos, pos], [buffers.nrm, nrm], [buffers.col, col], [buffers.lines, lines]]) {
        gl.bindBuffer(gl.ARRAY_BUFFER, buf);
        gl.bufferData(gl.ARRAY_BUFFER, arr, gl.STATIC_DRAW);
      }
      faceVertices = nf * 6;
      lineVertices = nf * 8;
      triangles = nf * 2;
    }

    const initial = () => mul(rotation(0, 0.4), rotation(1, -0.85));
    const cam = { rot: initial(), dist: 2.3, panX: 0, panY: 0 };
    function draw() {
      const mvpView = mul(translation(cam.panX, cam.panY, -cam.dist), cam.rot);
      const mvp = mul(perspective(0.6, canvas.width / canvas.height, 0.05, 50), mvpView);
      gl.viewport(0, 0, canvas.width, canvas.height);
      gl.clearColor(0.957, 0.961, 0.969, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
      gl.useProgram(faceProg);
      gl.uniformMatrix4fv(gl.getUniformLocation(faceProg, 'uMvp'), false, mvp);
      gl.uniformMatrix4fv(gl.getUniformLocation(faceProg, 'uView'), false, cam.rot);
      const attrs = [['aPos', buffers.pos], ['aNrm', buffers.nrm], ['aCol', buffers.col]];
      for (const [name, buf] of attrs) {
        const loc = gl.getAttribLocation(faceProg, name);
        gl.bindBuffer(gl.ARRAY_BUFFER, buf);
        gl.enableVertexAttribArray(loc);
        gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
      }
      if (faceVertices > 0) gl.drawArrays(gl.TRIANGLES, 0, faceVertices);
      for (const [name] of attrs) gl.disableVertexAttribArray(gl.getAttribLocation(faceProg, name));
      if (ui.edges.checked && lineVertices > 0) {
        gl.useProgram(lineProg);
        gl.uniformMatrix4fv(gl.getUniformLocation(lineProg, 'uMvp'), false, mvp);
        const loc = gl.getAttribLocation(lineProg, 'aPos');
        gl.bindBuffer(gl.ARRAY_BUFFER, buffers.lines);
        gl.enableVertexAttribArray(loc);
        gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
        gl.drawArrays(gl.LINES, 0, lineVertices);
        gl.disableVertexAttribArray(loc);
      }
      const err = gl.getError();
      if (err !== gl.NO_ERROR) throw new Error('WebGL error ' + err);
      if (statusEl.dataset.state !== 'error') {
        const r = canvas.getBoundingClientRect();
        statusEl.dataset.state = 'ok';
        statusEl.dataset.triangles = String(triangles);
        statusEl.dataset.rect = [r.left + window.scrollX, r.top + window.scrollY, r.width, r.height].map(Math.round).join(',');
        statusEl.textContent = 'ok: ' + triangles + ' triangles drawn (' + data.info.cells + ' hexes embedded, ' +
          data.info.quads + ' quads)';
      }
    }
    let pending = false;
    function redraw() {
      if (pending) return;
      pending = true;
      requestAnimationFrame(() => { pending = false; draw(); });
    }

    for (const el of [ui.axis, ui.pos, ui.flip, ui.sjMax]) el.addEventListener('input', () => { rebuild(); redraw(); });
    ui.edges.addEventListener('input', redraw);
    document.getElementById('reset-view').addEventListener('click', () => {
      cam.rot = initial(); cam.dist = 2.3; cam.panX = cam.panY = 0; redraw();
    });
    let drag = null;
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const s = cam.dist * 0.0012;
        cam.panX += dx * s; cam.panY -= dy * s;
      } else {
        cam.rot = mul(rotation(1, dx * 0.01), mul(rotation(0, dy * 0.01), cam.rot));
      }
      redraw();
    });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      cam.dist = Math.min(Math.max(cam.dist * Math.exp(e.deltaY * 0.001), 0.3), 30);
      redraw();
    }, { passive: false });

    // A view can be set from the address: report.html#axis=y&cut=0.3&flip=1&sj=0.2&edges=0.
    const params = new URLSearchParams(location.hash.slice(1));
    const num = (name, lo, hi) => {
      const v = Number(params.get(name));
      return params.has(name) && Number.isFinite(v) ? Math.min(Math.max(v, lo), hi) : null;
    };
    const axis = ['x', 'y', 'z'].indexOf(params.get('axis'));
    if (axis >= 0) ui.axis.value = String(axis);
    if (num('cut', 0, 1) !== null) ui.pos.value = String(Math.round(1000 * num('cut', 0, 1)));
    if (num('sj', -1, 1) !== null) ui.sjMax.value = String(Math.round(100 * num('sj', -1, 1)));
    if (params.has('flip')) ui.flip.checked = params.get('flip') === '1';
    if (params.has('edges')) ui.edges.checked = params.get('edges') !== '0';

    // The first frame is drawn at once, not on an animation frame, so that a page captured
    // as soon as it has loaded (a headless screenshot) already shows the mesh.
    rebuild();
    draw();
  }

  drawLegend();
  loadData().then(start).catch((e) => fail(e && e.message ? e.message : String(e)));
})();
)js";

}  // namespace isohex::report_detail
