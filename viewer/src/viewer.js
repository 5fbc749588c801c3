// interpatch's viewer page: draws the construction that `interpatch view` embedded in
// #interpatch-data (docs/spec-format.md, "The viewer page", describes the data) with
// three.js. Everything it needs is in the page; it requests nothing.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const data = JSON.parse(document.getElementById('interpatch-data').textContent);

// {"dtype": "float32", "length", "base64"} as a Float32Array (little-endian, as
// every machine that runs a browser stores it).
function floats(array) {
  const text = atob(array.base64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
  return new Float32Array(bytes.buffer, 0, array.length);
}

// Positions on the page are float32 in a frame of the construction's own: measured
// from `origin` in units of `unit` (a power of two near half its size), so that a
// small part far from the origin keeps its shape. Curvatures and det J come in the
// same unit; the colourings and their legends show true values.
const frame = data.frame;
const trueValues = (values, scale, offset = 0) => Float64Array.from(values, (v) => v * scale + offset);

const colours = {
  background: 0x20232a, data: 0xff8c1a, net: 0xc8c8d0, isolines: 0x15171c, inverted: 0xff1744,
  du: 0xe53935, dv: 0x43a047, dw: 0x1e88e5,
};

// ---- scene, camera, controls ------------------------------------------------------
const container = document.getElementById('view');
// Multisampling costs a renderer without a GPU (SwiftShader) about a third more per
// frame: meshes finer than the default 257 x 257 are drawn without it.
const cells = data.surface ? (data.surface.shape[0] - 1) * (data.surface.shape[1] - 1) : 0;
const renderer = new THREE.WebGLRenderer({ antialias: cells <= 256 * 256, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(colours.background);
container.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
camera.up.set(0, 0, 1);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.4);
camera.add(sun);
sun.position.set(0.3, 0.6, 1);
scene.add(camera);
const controls = new OrbitControls(camera, renderer.domElement);
controls.screenSpacePanning = true;

function render() { renderer.render(scene, camera); }
controls.addEventListener('change', render);

function resize() {
  const w = container.clientWidth, h = container.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', () => { resize(); render(); });

// ---- colourings -------------------------------------------------------------------
function paletteAt(stops, t) {
  if (!Number.isFinite(t)) return [0.45, 0.45, 0.45];
  const x = Math.min(Math.max(t, 0), 1) * (stops.length - 1);
  const i = Math.min(Math.floor(x), stops.length - 2), f = x - i;
  return [0, 1, 2].map((c) => stops[i][c] + f * (stops[i + 1][c] - stops[i][c]));
}

// The range a colouring spans: all finite values, or for signed quantities
// (curvatures) symmetric about zero out to the 95th percentile of their sizes, so that a few extreme values (at a pole, a corner) do not wash out
// the rest; values beyond it take the end colours.
function rangeOf(values, signed) {
  const finite = [];
  for (const v of values) if (Number.isFinite(v)) finite.push(v);
  if (!finite.length) return [0, 0];
  if (!signed) {
    let lo = Infinity, hi = -Infinity;
    for (const v of finite) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    return [lo, hi];
  }
  const sizes = finite.map(Math.abs).sort((a, b) => a - b);
  const m = sizes[Math.min(sizes.length - 1, Math.floor(0.95 * sizes.length))];
  return [-m, m];
}

// A number as people read it: 4 significant digits, trailing zeros dropped
// (2.331e-7, 0.785, 12.5); the summary keeps integers whole and every digit in a title.
function fmt(x) {
  if (!Number.isFinite(x)) return String(x);
  const s = Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(3) : x.toPrecision(4);
  const [mantissa, exponent] = s.split('e');
  const m = mantissa.includes('.') ? mantissa.replace(/\.?0+$/, '') : mantissa;
  return exponent === undefined ? m : `${m}e${exponent}`;
}

function drawLegend(stops, range, label) {
  const bar = document.getElementById('legend-bar');
  const g = bar.getContext('2d');
  for (let x = 0; x < bar.width; ++x) {
    const c = paletteAt(stops, x / (bar.width - 1));
    g.fillStyle = `rgb(${c.map((v) => Math.round(255 * v)).join(',')})`;
    g.fillRect(x, 0, 1, bar.height);
  }
  document.getElementById('legend-min').textContent = fmt(range[0]);
  document.getElementById('legend-max').textContent = `${fmt(range[1])} ${label}`;
}

// ---- geometry helpers --------------------------------------------------------------
// Triangles of an nu x nv grid of vertices (u index slowest), two per cell.
function gridIndex(nu, nv) {
  const index = new Uint32Array((nu - 1) * (nv - 1) * 6);
  let k = 0;
  for (let i = 0; i + 1 < nu; ++i)
    for (let j = 0; j + 1 < nv; ++j) {
      const a = i * nv + j, b = a + nv;
      index.set([a, b, b + 1, a, b + 1, a + 1], k);
      k += 6;
    }
  return index;
}

// Polylines along both directions of an nu x nv grid of points `at(i, j)` (a
// function giving [x, y, z]): every `step` rows and columns, the last always; closed
// ones wrap around.
function gridLines(nu, nv, at, step, closed = [false, false]) {
  const seg = [];
  const rows = (n, s) => { const r = []; for (let i = 0; i < n; i += s) r.push(i); if (r[r.length - 1] !== n - 1) r.push(n - 1); return r; };
  for (const i of rows(nu, step[0])) for (let j = 0; j + 1 < nv + (closed[1] ? 1 : 0); ++j) seg.push(...at(i, j), ...at(i, (j + 1) % nv));
  for (const j of rows(nv, step[1])) for (let i = 0; i + 1 < nu + (closed[0] ? 1 : 0); ++i) seg.push(...at(i, j), ...at((i + 1) % nu, j));
  return new Float32Array(seg);
}

function lineSegments(positions, colour, opacity = 1) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: colour, transparent: opacity < 1, opacity }));
}

function points(positions, colour, size) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  return new THREE.Points(g, new THREE.PointsMaterial({ color: colour, size, sizeAttenuation: false }));
}

const shadedMaterial = () => new THREE.MeshPhongMaterial({
  vertexColors: true, side: THREE.DoubleSide, shininess: 25, specular: 0x222222,
  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
});

// ---- the construction ---------------------------------------------------------------
const groups = { model: new THREE.Group(), isolines: new THREE.Group(), net: new THREE.Group(), data: new THREE.Group() };
for (const g of Object.values(groups)) scene.add(g);
groups.net.visible = false;
const colourings = {};  // name -> {label, values, signed, paint(values, range, stops)}
const shown = [];  // what the page shows, for the panel's "Shown" list
let repaint = () => {};  // the current colouring, applied and drawn (set below)

function addSurface(s) {
  const [nu, nv] = s.shape;
  const pos = floats(s.positions), nrm = floats(s.normals);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  g.setAttribute('normal', new THREE.BufferAttribute(nrm, 3));
  const colour = new THREE.BufferAttribute(new Float32Array(pos.length), 3);
  g.setAttribute('color', colour);
  g.setIndex(new THREE.BufferAttribute(gridIndex(nu, nv), 1));
  groups.model.add(new THREE.Mesh(g, shadedMaterial()));
  const step = [Math.max(1, Math.round((nu - 1) / 16)), Math.max(1, Math.round((nv - 1) / 16))];
  const at = (i, j) => { const k = 3 * (i * nv + j); return [pos[k], pos[k + 1], pos[k + 2]]; };
  groups.isolines.add(lineSegments(gridLines(nu, nv, at, step), colours.isolines, 0.55));
  const height = new Float64Array(nu * nv);
  for (let k = 0; k < height.length; ++k) height[k] = pos[3 * k + 2] * frame.unit + frame.origin[2];
  const paint = (values, range, stops) => {
    const span = range[1] - range[0];
    for (let k = 0; k < values.length; ++k) colour.setXYZ(k, ...paletteAt(stops, span > 0 ? (values[k] - range[0]) / span : 0.5));
    colour.needsUpdate = true;
  };
  colourings.height = { label: 'height (z)', values: height, signed: false, paint };
  colourings.gaussian = { label: 'Gaussian curvature K', values: trueValues(floats(s.gaussian), 1 / frame.unit ** 2), signed: true, paint };
  colourings.mean = { label: 'mean curvature H', values: trueValues(floats(s.mean), 1 / frame.unit), signed: true, paint };
  shown.push(`surface: ${nu} × ${nv} samples${resolutionNote()}, isoparametric lines every ${step[0]} × ${step[1]}`);
}

function addVolume(v) {
  const [nu, nv, nw] = v.shape;
  const pos = floats(v.positions), det = floats(v.det_j);
  const index = (i, j, k) => (i * nv + j) * nw + k;
  // A sheet of the sample grid: axis fixed at `at`, the other two running.
  const sheet = (axis, at) => {
    const dims = [nu, nv, nw].filter((_, a) => a !== axis);
    const id = (a, b) => (axis === 0 ? index(at, a, b) : axis === 1 ? index(a, at, b) : index(a, b, at));
    const p = new Float32Array(dims[0] * dims[1] * 3), d = new Float32Array(dims[0] * dims[1]);
    for (let a = 0; a < dims[0]; ++a)
      for (let b = 0; b < dims[1]; ++b) {
        const n = id(a, b), m = a * dims[1] + b;
        p.set(pos.subarray(3 * n, 3 * n + 3), 3 * m);
        d[m] = det[n];
      }
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.BufferAttribute(p, 3));
    g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(p.length), 3));
    g.setIndex(new THREE.BufferAttribute(gridIndex(dims[0], dims[1]), 1));
    g.computeVertexNormals();
    const mesh = new THREE.Mesh(g, shadedMaterial());
    mesh.userData = { values: trueValues(d, frame.unit ** 3), height: trueValues(p.filter((_, k) => k % 3 === 2), frame.unit, frame.origin[2]) };
    const step = [Math.max(1, Math.round((dims[0] - 1) / 8)), Math.max(1, Math.round((dims[1] - 1) / 8))];
    const lines = lineSegments(gridLines(dims[0], dims[1], (a, b) => [p[3 * (a * dims[1] + b)], p[3 * (a * dims[1] + b) + 1], p[3 * (a * dims[1] + b) + 2]], step), colours.isolines, 0.5);
    return { mesh, lines };
  };
  const sheets = [];
  const faces = new THREE.Group();
  for (let axis = 0; axis < 3; ++axis)
    for (const at of [0, v.shape[axis] - 1]) {
      const s = sheet(axis, at);
      faces.add(s.mesh);
      groups.isolines.add(s.lines);
      sheets.push(s.mesh);
    }
  groups.model.add(faces);
  // One movable slice per direction, off at first.
  const slices = document.getElementById('slices');
  slices.insertAdjacentHTML('beforeend', '<label><input type="checkbox" id="show-faces" checked> faces</label>');
  document.getElementById('show-faces').addEventListener('change', (e) => { faces.visible = e.target.checked; render(); });
  const sliceMeshes = [null, null, null];
  ['u', 'v', 'w'].forEach((name, axis) => {
    const n = v.shape[axis];
    slices.insertAdjacentHTML('beforeend',
      `<div class="slice"><label><input type="checkbox" id="slice-${name}-on"> slice ${name} =
       <input type="range" id="slice-${name}" min="0" max="${n - 1}" value="${(n - 1) >> 1}">
       <span id="slice-${name}-value"></span></label></div>`);
    const holder = new THREE.Group();
    holder.visible = false;
    groups.model.add(holder);
    const place = () => {
      const i = Number(document.getElementById(`slice-${name}`).value);
      document.getElementById(`slice-${name}-value`).textContent = (i / (n - 1)).toFixed(3);
      if (sliceMeshes[axis]) { holder.remove(sliceMeshes[axis]); sliceMeshes[axis].geometry.dispose(); }
      sliceMeshes[axis] = sheet(axis, i).mesh;
      holder.add(sliceMeshes[axis]);
      repaint();
    };
    document.getElementById(`slice-${name}`).addEventListener('input', place);
    document.getElementById(`slice-${name}-on`).addEventListener('change', (e) => { holder.visible = e.target.checked; render(); });
    place();
  });
  // Cells with a corner where det J <= 0, marked at their centres.
  const marks = [];
  for (let i = 0; i + 1 < nu; ++i)
    for (let j = 0; j + 1 < nv; ++j)
      for (let k = 0; k + 1 < nw; ++k) {
        let bad = false;
        const c = [0, 0, 0];
        for (let n = 0; n < 8; ++n) {
          const m = index(i + (n >> 2), j + ((n >> 1) & 1), k + (n & 1));
          if (!(det[m] > 0)) bad = true;
          for (let a = 0; a < 3; ++a) c[a] += pos[3 * m + a] / 8;
        }
        if (bad) marks.push(...c);
      }
  if (marks.length) groups.model.add(points(new Float32Array(marks), colours.inverted, 7));
  const all = () => [...sheets, ...sliceMeshes.filter((m) => m)];
  const paintSheets = (key) => (_, range, stops) => {
    const span = range[1] - range[0];
    for (const m of all()) {
      const values = m.userData[key], colour = m.geometry.getAttribute('color');
      for (let k = 0; k < values.length; ++k) colour.setXYZ(k, ...paletteAt(stops, span > 0 ? (values[k] - range[0]) / span : 0.5));
      colour.needsUpdate = true;
    }
  };
  const heights = new Float64Array(pos.length / 3);
  for (let k = 0; k < heights.length; ++k) heights[k] = pos[3 * k + 2] * frame.unit + frame.origin[2];
  colourings.det_j = { label: 'det J', values: trueValues(det, frame.unit ** 3), signed: false, paint: paintSheets('values') };
  colourings.height = { label: 'height (z)', values: heights, signed: false, paint: paintSheets('height') };
  shown.push(`volume: ${nu} × ${nv} × ${nw} samples${resolutionNote()}; ${marks.length / 3} cells with a corner where det J ≤ 0 marked in red`);
}

function resolutionNote() {
  const { asked, shown: s } = data.resolution;
  return asked.join() === s.join() ? '' : ` (asked ${asked.filter((n) => n).join(' × ')}, decimated for display)`;
}

function addControlNet(net) {
  const p = floats(net.points), shape = net.shape;
  const sizes = (a, b) => `${a.join(' × ')}${a.join() === b.join() ? '' : ` of ${b.join(' × ')}`}`;
  if (shape.length === 2) {
    const [n, m] = shape;
    const at = (i, j) => { const k = 3 * (i * m + j); return [p[k], p[k + 1], p[k + 2]]; };
    const full = net.shape.join() === net.full_shape.join();
    groups.net.add(lineSegments(gridLines(n, m, at, [1, 1], full ? net.periodic : [false, false]), colours.net, 0.8));
  } else {
    const [n, m, l] = shape;
    const at3 = (i, j, k) => { const q = 3 * ((i * m + j) * l + k); return [p[q], p[q + 1], p[q + 2]]; };
    for (let i = 0; i < n; ++i) groups.net.add(lineSegments(gridLines(m, l, (j, k) => at3(i, j, k), [1, 1]), colours.net, 0.6));
    for (let j = 0; j < m; ++j) for (let k = 0; k < l; ++k) {
      const seg = [];
      for (let i = 0; i + 1 < n; ++i) seg.push(...at3(i, j, k), ...at3(i + 1, j, k));
      groups.net.add(lineSegments(new Float32Array(seg), colours.net, 0.6));
    }
  }
  groups.net.add(points(p, colours.net, 4));
  shown.push(`control net: ${sizes(shape, net.full_shape)} points`);
}

function addData(sets) {
  for (const d of sets) {
    const p = floats(d.points);
    if (d.kind === 'curve') {
      const seg = [];
      for (let k = 0; k + 1 < p.length / 3; ++k) seg.push(...p.subarray(3 * k, 3 * k + 6));
      groups.data.add(lineSegments(new Float32Array(seg), colours.data));
    } else {
      const n = p.length / 3;
      groups.data.add(points(p, colours.data, n > 5000 ? 2 : n > 200 ? 3 : 6));
    }
    const full = d.full_shape.join(' × '), kept = d.shape.join(' × ');
    shown.push(`data ${d.pointer}: ${d.kind === 'curve' ? 'curve, ' : ''}${kept}${kept === full ? '' : ` of ${full}`} points`);
  }
}

function addFrames(frames) {
  for (const f of frames) {
    const origin = new THREE.Vector3(...f.p.map((x, a) => x / frame.unit - frame.origin[a] / frame.unit));
    for (const [key, colour] of [['du', colours.du], ['dv', colours.dv], ['dw', colours.dw]]) {
      if (!f[key]) continue;
      const d = new THREE.Vector3(...f[key]).divideScalar(frame.unit);
      const length = d.length() / 3;  // a third of the derivative: the Bézier handle of a cubic Hermite patch or volume
      if (length > 0) groups.data.add(new THREE.ArrowHelper(d.normalize(), origin, length, colour, 0.2 * length, 0.1 * length));
    }
  }
  if (frames.length) shown.push(`corner frames: S_u (red), S_v (green)${frames[0].dw ? ', S_w (blue)' : ''} at ${frames.map((f) => f.at).join(', ')}, a third of their length`);
}

// ---- the summary: the numbers `interpatch info` prints --------------------------------
function addInfo(info) {
  const rows = [];
  const add = (key, label, value) => { if (value !== undefined && value !== null) rows.push([key, label, value]); };
  // shown: counts whole, other numbers to 4 digits; full: every digit, for the title.
  const text = (v, number) => (Array.isArray(v) ? v.map((x) => text(x, number)).join(' × ')
    : typeof v === 'object' && v !== null ? Object.entries(v).map(([k, x]) => `${k}: ${text(x, number)}`).join(', ')
      : typeof v === 'number' ? number(v) : String(v));
  const shown = (x) => (Number.isInteger(x) ? String(x) : fmt(x));
  add('type', 'type', info.type);
  add('kind', 'kind', info.kind);
  add('exact_form', 'exact form', info.exact_form ?? `none: ${info.no_exact_form}`);
  add('degree', 'degree', info.degree);
  add('control_points', 'control points', info.control_points);
  add('rational', 'rational', info.rational);
  if (info.periodic && info.periodic.some((p) => p)) add('periodic', 'closed', info.periodic);
  add('continuity', 'continuity', info.continuity);
  const e = info.max_data_error;
  if (e) {
    add('max_data_error.absolute', 'max error at the data', e.absolute);
    add('max_data_error.relative', 'relative to the diagonal', e.relative);
    add('max_data_error.points', 'data points checked', e.points);
    add('max_data_error.at', 'worst at', e.at);
  } else {
    add('max_data_error', 'max error at the data', 'no data points');
  }
  if (info.bounding_box) add('bounding_box.diagonal', 'diagonal of the control net box', info.bounding_box.diagonal);
  const j = info.jacobian;
  if (j) {
    add('jacobian.min_determinant', 'min det J', j.min_determinant);
    add('jacobian.max_determinant', 'max det J', j.max_determinant);
    add('jacobian.inverted_cells', `inverted cells of ${j.cells} (${j.samples_per_direction}³ samples)`, j.inverted_cells);
  }
  add('warnings', 'warnings', info.warnings && info.warnings.length ? info.warnings.join('; ') : 'none');
  const table = document.getElementById('info');
  for (const [key, label, value] of rows) {
    const tr = table.insertRow();
    tr.dataset.key = key;
    tr.insertCell().textContent = label;
    const td = tr.insertCell();
    td.textContent = text(value, shown);
    const full = text(value, String);
    if (full !== td.textContent) td.title = full;
    td.dataset.value = JSON.stringify(value);
  }
}

// ---- putting it together ---------------------------------------------------------------
document.getElementById('title').textContent = data.title;
if (data.kind === 'surface') addSurface(data.surface);
else addVolume(data.volume);
if (data.control_net) addControlNet(data.control_net);
else document.getElementById('show-net').disabled = true;
addData(data.data);
addFrames(data.frames);
addInfo(data.info);
document.getElementById('shown').innerHTML = shown.map((s) => `<li>${s.replace(/&/g, '&amp;').replace(/</g, '&lt;')}</li>`).join('');

const select = document.getElementById('colouring');
for (const [name, c] of Object.entries(colourings)) select.add(new Option(c.label, name));
repaint = () => {
  const c = colourings[select.value];
  const signed = c.signed;
  const range = rangeOf(c.values, signed);
  const stops = signed ? data.palettes.signed : data.palettes.height;
  c.paint(c.values, range, stops);
  drawLegend(stops, range, c.label);
  render();
};
select.addEventListener('change', repaint);

const toggle = (id, group) => document.getElementById(id).addEventListener('change', (e) => { group.visible = e.target.checked; render(); });
toggle('show-isolines', groups.isolines);
toggle('show-net', groups.net);
toggle('show-data', groups.data);

// The first view: the whole model from the side of -y and +x, 35 degrees up.
const box = new THREE.Box3().setFromObject(groups.model);
const sphere = box.getBoundingSphere(new THREE.Sphere());
const radius = Math.max(sphere.radius, 1e-9);
const yaw = Math.PI / 4, pitch = 35 * Math.PI / 180;
// The bounding sphere seen whole is a generous bound: most shapes fill little of it.
const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.9;
camera.position.copy(sphere.center).add(new THREE.Vector3(Math.sin(yaw) * Math.cos(pitch), -Math.cos(yaw) * Math.cos(pitch), Math.sin(pitch)).multiplyScalar(distance));
camera.near = distance / 100;
camera.far = distance * 100;
controls.target.copy(sphere.center);
controls.update();
controls.saveState();
document.getElementById('reset').addEventListener('click', () => { controls.reset(); render(); });
resize();
repaint();  // draws the first picture
// Drawn: the milliseconds since the page's navigation began (tools/bench_viewer.py).
document.body.dataset.readyMs = String(performance.now());
document.body.dataset.ready = 'true';
