// The page of `elastic studio` (docs/studio.md): two views (source, target) of the limit surfaces
// the server sends, region picking by clicks, a map run streamed from the server, the result
// painted and as a heatmap beside a baseline, and live warm re-solves while the target region is
// dragged. All geometry comes from the server; the page only draws and sends clicks.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls.js';

const $ = (id) => document.getElementById(id);

// What the browser test reads (tests/studio): the specs shown, the raw click, the run's state,
// how many times the views were drawn (`renders`; `resultDrawnAt` is its value when the result was
// put in the scene, so a later draw shows it) and whether a live re-solve is pending (`liveBusy`).
const studio = {
  ready: false, status: 'idle', lastHit: null, lastSnap: null, error: '',
  specs: { source: null, target: null }, result: null, live: null, liveLog: [], frames: 0,
  renders: 0, resultDrawnAt: -1,
};
window.studio = studio;

// ---------------------------------------------------------------- server calls
async function call(path, body) {
  const options = body === undefined ? {} : {
    method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body),
  };
  const response = await fetch(path, options);
  const answer = await response.json();
  if (!response.ok) throw new Error(answer.error || `${path}: HTTP ${response.status}`);
  return answer;
}

function showError(message) {
  studio.error = message || '';
  $('error').textContent = studio.error;
}

async function guarded(work) {
  try {
    showError('');
    return await work();
  } catch (e) {
    showError(e.message);
    return undefined;
  }
}

// ---------------------------------------------------------------- views
// The views are drawn only when something changed (software WebGL on a machine without a GPU
// would otherwise spend whole cores redrawing still pictures).
let dirty = true;
function invalidate() { dirty = true; }

class View {
  constructor(element) {
    this.element = element;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    element.appendChild(this.renderer.domElement);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xf4f5f7);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x555566, 2.2));
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
    this.camera.add(new THREE.DirectionalLight(0xffffff, 1.4));
    this.scene.add(this.camera);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.mouseButtons = {
      LEFT: THREE.MOUSE.ROTATE, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.ROTATE,
    };
    this.surface = null;   // the limit tessellation
    this.overlays = new THREE.Group();   // outline, markers, particles, grid
    const add = this.overlays.add.bind(this.overlays);
    this.overlays.add = (...objects) => { invalidate(); return add(...objects); };
    this.scene.add(this.overlays);
    this.controls.addEventListener('change', invalidate);
    this.diagonal = 1;
    this.radius = 1;  // of the surface's bounding sphere
    new ResizeObserver(() => this.resize()).observe(element);
    this.resize();
  }

  // How far from its centre the camera sees the bounding sphere whole at the current aspect.
  fitDistance() {
    const half = THREE.MathUtils.degToRad(this.camera.fov / 2);
    const narrow = Math.min(half, Math.atan(Math.tan(half) * this.camera.aspect));
    return (1.1 * this.radius) / Math.sin(narrow);
  }

  resize() {
    const w = Math.max(1, this.element.clientWidth), h = Math.max(1, this.element.clientHeight);
    const before = this.surface ? this.fitDistance() : 0;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    if (this.surface) {
      // Keep the user's zoom relative to a whole view of the model (a view that narrows when the
      // baseline's appears moves back).
      const offset = this.camera.position.clone().sub(this.controls.target);
      this.camera.position.copy(this.controls.target)
        .add(offset.multiplyScalar(this.fitDistance() / before));
      this.controls.update();
    }
    invalidate();
  }

  setSurface(data) {
    if (this.surface) { this.scene.remove(this.surface); this.surface.geometry.dispose(); }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(data.positions, 3));
    geometry.setIndex(data.indices);
    if (data.uv) geometry.setAttribute('uv', new THREE.Float32BufferAttribute(data.uv, 2));
    geometry.computeVertexNormals();
    geometry.computeBoundingSphere();
    const material = new THREE.MeshStandardMaterial({
      color: 0xb8c4d6, roughness: 0.8, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    if (data.uv && data.texture) {
      material.map = new THREE.TextureLoader().load(fileUrl(data.texture), invalidate);
      material.map.colorSpace = THREE.SRGBColorSpace;
      material.color.set(0xffffff);
    }
    this.surface = new THREE.Mesh(geometry, material);
    this.scene.add(this.surface);
    invalidate();
    this.diagonal = data.diagonal;
    const sphere = geometry.boundingSphere;
    this.controls.target.copy(sphere.center);
    this.camera.near = sphere.radius / 100;
    this.camera.far = sphere.radius * 100;
    this.radius = sphere.radius;
    this.camera.position.copy(sphere.center).add(new THREE.Vector3(0, 0, this.fitDistance()));
    this.camera.updateProjectionMatrix();
    this.controls.update();
  }

  // The surface point under a pointer event (null off the surface).
  hit(event) {
    if (!this.surface) return null;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1,
      -((event.clientY - rect.top) / rect.height) * 2 + 1);
    const ray = new THREE.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    const hits = ray.intersectObject(this.surface, false);
    return hits.length ? hits[0].point : null;
  }

  clearOverlays(keep = () => false) {
    invalidate();
    for (const child of [...this.overlays.children]) {
      if (keep(child)) continue;
      this.overlays.remove(child);
      child.geometry?.dispose();
    }
  }

  render(camera = this.camera) { this.renderer.render(this.scene, camera); }
}

function fileUrl(path) { return `api/file?path=${encodeURIComponent(path)}`; }

const views = { source: new View($('source-view')), target: new View($('target-view')) };
// For the browser test: whether a page pixel shows the side's surface.
studio.onSurface = (side, clientX, clientY) => Boolean(views[side].hit({ clientX, clientY }));
const baselineView = new View($('baseline-view'));
baselineView.controls.enabled = false;
const loaded = { source: null, target: null };

function outlineObject(flat, color) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(flat, 3));
  const line = new THREE.LineLoop(geometry, new THREE.LineBasicMaterial({ color, depthTest: true }));
  line.name = 'outline';
  return line;
}

function marker(position, color, size) {
  const m = new THREE.Mesh(new THREE.SphereGeometry(size, 12, 8),
    new THREE.MeshBasicMaterial({ color }));
  m.position.set(position[0], position[1], position[2]);
  m.name = 'marker';
  return m;
}

// ---------------------------------------------------------------- regions
// Each side's region being edited: a disk (centre, radius) or a polygon (points), and an anchor.
const regions = {
  source: { kind: null, center: null, radius: 0, points: [], anchor: null, spec: null },
  target: { kind: null, center: null, radius: 0, points: [], anchor: null, spec: null },
};

function diskSpec(region) {
  const c = region.center.map((x) => Number(x.toPrecision(7)));
  return `disk:${c.join(',')},${Number(region.radius.toPrecision(6))}`;
}

function regionRequest(side) {
  const r = regions[side];
  if (r.kind === 'disk') return { side, spec: diskSpec(r), anchor: r.anchor };
  if (r.kind === 'points' && r.points.length >= 3) return { side, points: r.points, anchor: r.anchor };
  return null;
}

function drawMarkers(side) {
  const view = views[side], r = regions[side], size = view.diagonal * 0.006;
  view.clearOverlays((c) => c.name !== 'marker');
  if (r.kind === 'disk' && r.center) view.overlays.add(marker(r.center, 0xff6a00, size));
  if (r.kind === 'points') for (const p of r.points) view.overlays.add(marker(p, 0x1f6feb, size));
  if (r.anchor) view.overlays.add(marker(r.anchor, 0x00a36c, size * 1.3));
}

function showSpec(side, spec) {
  regions[side].spec = spec;
  studio.specs[side] = spec;
  $(`${side}-spec`).textContent = spec || 'no region';
}

// The exact cut outline of the region as edited, from the server; one request at a time, the
// latest edit wins.
const outlineQueue = { source: { busy: false, again: false }, target: { busy: false, again: false } };
async function updateOutline(side) {
  const q = outlineQueue[side];
  if (q.busy) { q.again = true; return; }
  const request = regionRequest(side);
  drawMarkers(side);
  if (!request) return;
  q.busy = true;
  try {
    const answer = await guarded(() => call('api/region', request));
    const view = views[side];
    view.clearOverlays((c) => c.name !== 'outline');
    if (answer) {
      view.overlays.add(outlineObject(answer.outline, side === 'source' ? 0xff6a00 : 0x0077cc));
      showSpec(side, answer.spec);
    }
  } finally {
    q.busy = false;
    if (q.again) { q.again = false; updateOutline(side); }
  }
}

async function snapped(side, point) {
  const answer = await call('api/snap', { side, point: [point.x, point.y, point.z] });
  studio.lastSnap = answer.position;
  return answer.position;
}

// Picking on one view. The snap to the limit surface is a server round trip, so a gesture may move
// (or end) before its press is snapped: moves made meanwhile are kept and the last one is applied
// once the press is known.
function attachPicking(side) {
  const view = views[side], canvas = view.renderer.domElement;
  let drag = null;  // the gesture being dragged: {mode: 'radius'|'move', ready, last}
  const dragTo = (gesture, hit) => {
    const r = regions[side];
    if (gesture.mode === 'radius') {
      const d = new THREE.Vector3(...r.center).distanceTo(hit);
      if (d <= view.diagonal * 0.005) return;
      r.radius = d;
    } else {
      r.center = [hit.x, hit.y, hit.z];
    }
    edited(side);
  };
  canvas.addEventListener('pointerdown', async (event) => {
    if (event.button !== 0) return;
    const hit = view.hit(event);
    if (!hit) return;  // the background: orbit
    view.controls.enabled = false;
    canvas.setPointerCapture(event.pointerId);
    studio.lastHit = [hit.x, hit.y, hit.z];
    const r = regions[side];
    const mode = event.altKey ? 'anchor' : event.shiftKey ? 'point'
      : event.ctrlKey && r.kind === 'disk' ? 'move' : 'radius';
    const gesture = { mode, ready: false, last: null };
    if (mode === 'radius' || mode === 'move') drag = gesture;
    const p = await guarded(() => snapped(side, hit));
    if (!p) return;
    if (mode === 'anchor') {
      r.anchor = p;
    } else if (mode === 'point') {
      if (r.kind !== 'points') { r.kind = 'points'; r.points = []; }
      r.points.push(p);
    } else {
      if (mode === 'radius') {
        r.kind = 'disk';
        if (!r.radius) r.radius = view.diagonal * 0.12;
      }
      r.center = p;
    }
    gesture.ready = true;
    if (gesture.last) dragTo(gesture, gesture.last);
    else await edited(side);
  });
  canvas.addEventListener('pointermove', (event) => {
    if (!drag) return;
    const hit = view.hit(event);
    if (!hit) return;
    if (drag.ready) dragTo(drag, hit);
    else drag.last = hit;
  });
  const end = () => {
    // The drag's last live update was budgeted: converge where the region stopped.
    if (drag && side === 'target' && liveApplies()) resolveLive(true);
    drag = null;
    view.controls.enabled = true;
  };
  canvas.addEventListener('pointerup', end);
  canvas.addEventListener('pointercancel', end);
}

// A region changed: redraw its outline and, on the target after a finished map, re-solve live.
function liveApplies() {
  return $('live').checked && studio.result && regions.target.kind === 'disk';
}

async function edited(side) {
  if (side === 'target' && liveApplies()) {
    resolveLive(false);
  } else {
    await updateOutline(side);
  }
}

// ---------------------------------------------------------------- live warm re-solve
// While the region is dragged each update gets a time budget (the relaxation continues from the
// previous update's placement); when the drag ends the map converges. One request at a time; the
// latest edit wins, a final solve is never dropped.
const kLiveBudgetSeconds = 0.1;
const live = { busy: false, again: false, final: false };
Object.defineProperty(studio, 'liveBusy', { enumerable: true, get: () => live.busy || live.again });
async function resolveLive(final) {
  if (live.busy) {
    live.again = true;
    live.final = live.final || final;
    return;
  }
  live.busy = true;
  const r = regions.target;
  drawMarkers('target');
  const started = performance.now();
  try {
    const answer = await guarded(() => call('api/resolve',
      { spec: diskSpec(r), anchor: r.anchor, budget_seconds: final ? 0 : kLiveBudgetSeconds }));
    if (answer) {
      showSpec('target', answer.spec);
      const view = views.target;
      view.clearOverlays((c) => c.name !== 'outline');
      view.overlays.add(outlineObject(answer.outline, 0x0077cc));
      // Redraws (another Show mode) keep the live placement; the heatmap's colours stay the cold
      // run's until the next Run.
      if (lastResult) lastResult.methods[0].positions = answer.positions;
      if (gridMeshes.elastic) {
        gridMeshes.elastic.geometry.setAttribute('position',
          new THREE.Float32BufferAttribute(answer.positions, 3));
        gridMeshes.elastic.geometry.computeVertexNormals();
        invalidate();
      }
      studio.live = { ...answer, positions: undefined, outline: undefined,
        final, page_seconds: (performance.now() - started) / 1000 };
      studio.liveLog.push(studio.live);
      $('status').textContent = `live re-solve${final ? '' : ' (budgeted)'}: ` +
        `${answer.iterations} iterations, ${answer.converged ? 'converged' : 'not converged yet'}, ` +
        `${(answer.seconds * 1000).toFixed(0)} ms on the server ` +
        `(region ${(answer.seconds_region * 1000).toFixed(0)} ms), ${answer.folds} folds` +
        ' — Run for the saved (cold) map';
    }
  } finally {
    live.busy = false;
    if (live.again) {
      const next = live.final;
      live.again = false;
      live.final = false;
      resolveLive(next);
    }
  }
}

// ---------------------------------------------------------------- loading
async function load(side, path) {
  const data = await guarded(() => call('api/load', { side, path }));
  if (data) showSurface(side, data);
}

function showSurface(side, data) {
  loaded[side] = data;
  $(`${side}-path`).value = data.path;
  views[side].setSurface(data);
  views[side].clearOverlays();
  regions[side] = { kind: null, center: null, radius: 0, points: [], anchor: null, spec: null };
  if (side === 'source' && data.kind === 'image') showSpec('source', 'rectangle');
  else showSpec(side, null);
  if (side === 'target') clearResult();
  if (data.warnings && data.warnings.length) $('status').textContent = data.warnings.join('; ');
}

// ---------------------------------------------------------------- run and result
const gridMeshes = { elastic: null, baseline: null };
let particlesObject = null;

function clearResult() {
  studio.result = null;
  for (const key of ['elastic', 'baseline']) gridMeshes[key] = null;
  views.target.clearOverlays((c) => c.name !== 'grid' && c.name !== 'particles');
  baselineView.clearOverlays();
  $('baseline-view').classList.add('hidden');
  $('legend').classList.add('hidden');
  $('metrics').classList.add('hidden');
  for (const id of ['save-job', 'save-report']) $(id).classList.add('disabled');
}

function jobOfPage() {
  const job = { particles: Number($('particles').value) };
  const source = loaded.source, target = loaded.target;
  if (source) job[source.kind === 'image' ? 'source-image' : 'source'] = source.path;
  if (target) job.target = target.path;
  if (regions.source.spec) job['source-region'] = regions.source.spec;
  if (regions.target.spec) job['target-region'] = regions.target.spec;
  return job;
}

async function run() {
  clearResult();
  const started = await guarded(() => call('api/map', jobOfPage()));
  if (!started) return;
  studio.status = 'running';
  studio.frames = 0;
  follow(started.run);
}

// Progress and frames stream from the server (server-sent events) until the run ends.
let stream = null;
function follow(runId) {
  if (stream) stream.close();
  stream = new EventSource('api/stream');
  stream.onmessage = (message) => {
    const state = JSON.parse(message.data);
    if (state.run !== runId) return;
    // 'done' once the result is shown (showResult).
    if (state.status !== 'done') studio.status = state.status;
    const energy = state.energy ? `, energy ${state.energy.toPrecision(4)}` : '';
    $('status').textContent = `${state.status}: ${state.stage}` +
      (state.iteration ? ` ${state.iteration}${state.total ? '/' + state.total : ''}` : '') + energy;
    if (state.frame) showFrame(state.frame);
    if (state.status === 'done' || state.status === 'failed') {
      stream.close();
      stream = null;
      if (state.message) showError(state.message);
      if (state.status === 'done') showResult();
    }
  };
}

function showFrame(flat) {
  studio.frames += 1;
  const view = views.target;
  if (particlesObject) { view.overlays.remove(particlesObject); particlesObject.geometry.dispose(); }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(flat, 3));
  particlesObject = new THREE.Points(geometry,
    new THREE.PointsMaterial({ color: 0x1a1a1a, size: 3, sizeAttenuation: false }));
  particlesObject.name = 'particles';
  view.overlays.add(particlesObject);
}

// A 3D checkerboard of the source positions: a painted look for sources without a texture.
function checkerColors(source, diagonal) {
  const cell = diagonal / 16, colors = new Float32Array(source.length);
  for (let i = 0; i < source.length; i += 3) {
    const parity = (Math.floor(source[i] / cell) + Math.floor(source[i + 1] / cell) +
      Math.floor(source[i + 2] / cell)) & 1;
    const c = parity ? [0.93, 0.55, 0.18] : [0.16, 0.38, 0.75];
    colors.set(c, i);
  }
  return colors;
}

function gridMesh(grid, method, mode) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(method.positions, 3));
  geometry.setIndex(grid.triangles);
  geometry.computeVertexNormals();
  const options = { side: THREE.DoubleSide, roughness: 0.9 };
  if (mode === 'heatmap') {
    geometry.setAttribute('color', new THREE.Float32BufferAttribute(method.colors, 3));
    options.vertexColors = true;
  } else if (mode === 'paint') {
    const source = loaded.source;
    if (grid.uv && source && source.texture) {
      geometry.setAttribute('uv', new THREE.Float32BufferAttribute(grid.uv, 2));
      options.map = new THREE.TextureLoader().load(fileUrl(source.texture), invalidate);
      options.map.colorSpace = THREE.SRGBColorSpace;
    } else {
      geometry.setAttribute('color',
        new THREE.BufferAttribute(checkerColors(grid.source, source ? source.diagonal : 1), 3));
      options.vertexColors = true;
    }
  } else {
    options.color = 0xffffff;
    options.wireframe = true;
  }
  const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial(options));
  mesh.name = 'grid';
  return mesh;
}

async function showResult() {
  const result = await guarded(() => call(`api/result?baseline=${$('baseline').value}`));
  if (!result) return;
  studio.result = {
    run: result.run, verdict: result.verdict, legend: result.legend,
    methods: result.methods.map((m) => ({ name: m.name, ok: m.ok, status: m.status, metrics: m.metrics })),
  };
  lastResult = result;
  if (particlesObject) { views.target.overlays.remove(particlesObject); particlesObject = null; }
  drawResult();
  for (const id of ['save-job', 'save-report']) $(id).classList.remove('disabled');
  const legend = result.legend;
  $('legend-metric').textContent = legend.metric;
  $('legend-low').textContent = legend.low.toPrecision(3);
  $('legend-high').textContent = legend.high.toPrecision(3);
  $('legend').classList.remove('hidden');
  const keys = ['status', 'folds', 'sigma_min', 'symmetric_dirichlet', 'length_energy',
    'angle_error_mean_deg', 'seconds'];
  const rows = [`<tr><th>method</th>${keys.map((k) => `<th>${k}</th>`).join('')}</tr>`];
  for (const m of result.methods) {
    const cells = keys.map((k) => {
      if (k === 'status') return m.ok ? m.status : `failed: ${m.error}`;
      const v = m.metrics ? m.metrics[k] : undefined;
      return typeof v === 'number' ? Number(v.toPrecision(4)) : '';
    });
    rows.push(`<tr><th>${m.name}</th>${cells.map((c) => `<td>${c}</td>`).join('')}</tr>`);
  }
  $('metrics').innerHTML = rows.join('');
  $('metrics').classList.remove('hidden');
  $('status').textContent = result.verdict.ok ? 'done: converged, no folds' :
    `done: ${result.verdict.failure}`;
  studio.status = 'done';
}

let lastResult = null;
function drawResult() {
  if (!lastResult) return;
  const mode = $('show').value, result = lastResult;
  studio.resultDrawnAt = studio.renders;
  views.target.clearOverlays((c) => c.name !== 'grid');
  baselineView.clearOverlays();
  const [elastic, baseline] = result.methods;
  gridMeshes.elastic = gridMesh(result.grid, elastic, mode);
  views.target.overlays.add(gridMeshes.elastic);
  if (baseline && baseline.ok) {
    // The baseline's view shows the target surface under the baseline's grid, seen by the target
    // view's camera.
    if (!baselineView.surface && loaded.target) baselineView.setSurface(loaded.target);
    gridMeshes.baseline = gridMesh(result.grid, baseline, mode);
    baselineView.overlays.add(gridMeshes.baseline);
    $('baseline-name').textContent = baseline.name;
    $('baseline-view').classList.remove('hidden');
  } else {
    $('baseline-view').classList.add('hidden');
  }
}

// ---------------------------------------------------------------- wiring
for (const side of ['source', 'target']) {
  attachPicking(side);
  $(`${side}-load`).addEventListener('click', () => load(side, $(`${side}-path`).value));
}
for (const button of document.querySelectorAll('button.clear')) {
  button.addEventListener('click', () => {
    const side = button.dataset.side;
    regions[side] = { kind: null, center: null, radius: 0, points: [], anchor: null, spec: null };
    views[side].clearOverlays((c) => c.name === 'grid');
    showSpec(side, side === 'source' && loaded.source?.kind === 'image' ? 'rectangle' : null);
  });
}
$('run').addEventListener('click', run);
$('cancel').addEventListener('click', () => guarded(() => call('api/cancel', {})));
$('show').addEventListener('change', drawResult);
window.addEventListener('resize', invalidate);
$('baseline').addEventListener('change', () => { if (studio.result) showResult(); });

function animate() {
  if (dirty) {
    dirty = false;
    for (const view of Object.values(views)) view.render();
    if (!$('baseline-view').classList.contains('hidden')) baselineView.render(views.target.camera);
    studio.renders += 1;
  }
  requestAnimationFrame(animate);
}

async function start() {
  const state = await guarded(() => call('api/state'));
  for (const side of ['source', 'target']) {
    if (state && state.loaded[side]) {
      const data = await guarded(() => call(`api/surface?side=${side}`));
      if (data) showSurface(side, data);
    }
  }
  studio.ready = true;
  animate();
}
start();
