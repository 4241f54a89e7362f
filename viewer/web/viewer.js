// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors
//
// The page of `pointform view`: reads /api/info, then loads every layer (the files named on the
// command line): a hierarchy's levels streamed coarse to fine from /api/layer/<k>/level/<i>
// (each level's vertices are a prefix of the next, so every answer only carries the vertices
// new at that level and is appended), a mesh as one level, a point cloud from
// /api/layer/<k>/points. On the samples (the first point cloud) a base mesh can be picked by
// hand and reconstructed on the server (POST /api/reconstruct); the result arrives as a new
// layer. Binary layouts: docs/viewer.md. Test hook: window.pointform.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { PickedBaseMesh } from './base_mesh.js';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const statusLine = $('status');
const slider = $('level');
const sliderValue = $('level-value');
const wireframeBox = $('wireframe');
const baseBox = $('base-overlay');
const distanceBox = $('distance');
const legend = $('legend');
const figures = $('figures');
const layerList = $('layers');

// preserveDrawingBuffer: the picture export and the browser test read the canvas back.
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(0xf4f4f2, 1);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
const controls = new OrbitControls(camera, canvas);
scene.add(new THREE.HemisphereLight(0xffffff, 0x606070, 1.6));
const headlight = new THREE.DirectionalLight(0xffffff, 1.6);
camera.add(headlight);
scene.add(camera);

const surfaceMaterial = new THREE.MeshPhongMaterial({
  color: 0x8fa3bf, specular: 0x222222, shininess: 30, side: THREE.DoubleSide,
  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
});
const distanceMaterial = surfaceMaterial.clone();
distanceMaterial.color.set(0xffffff);
distanceMaterial.vertexColors = true;
const baseMaterial = new THREE.LineBasicMaterial({ color: 0xd04a1c });

let info = null;
let sceneOrigin = [0, 0, 0];  // world coordinates of the scene's 0: the first layer's origin
const layers = [];            // per layer: { info, group, levels, positions, object, ... }
let active = null;            // the surface layer the slider, figures and test hook act on
let samples = null;           // the samples' layer (the first point cloud), or null
let followStream = true;      // show each level as it arrives until the user picks one
let baseOverlay = null;
let colorByDistance = false;
let resolveReady;
const readyPromise = new Promise((resolve) => { resolveReady = resolve; });
let allArrived = false;

function render() {
  renderer.render(scene, camera);
}

function resize() {
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) ||
      canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
  }
  camera.aspect = w / Math.max(h, 1);
  // The picture's centre moved right by half the panel's width, when there is room, so that
  // the framed scene is not under the panel.
  const panelWidth = $('panel').offsetWidth + 8;
  if (w > 2.5 * panelWidth) camera.setViewOffset(w, h, -panelWidth / 2, 0, w, h);
  else camera.clearViewOffset();
  camera.updateProjectionMatrix();
  render();
}

/** A layer's box in scene coordinates (its own origin moved to the scene's). */
function sceneBox(layerInfo) {
  const shift = layerInfo.origin.map((o, k) => o - sceneOrigin[k]);
  return new THREE.Box3(
    new THREE.Vector3(...layerInfo.bounding_box.min.map((x, k) => x + shift[k])),
    new THREE.Vector3(...layerInfo.bounding_box.max.map((x, k) => x + shift[k])));
}

function sceneBounds() {
  const box = new THREE.Box3();
  for (const l of info.layers) box.union(sceneBox(l));
  return box;
}

/** Looks at the whole scene from `direction` (scene coordinates; default a three-quarter view). */
function frame(direction = [0.35, 0.25, 1]) {
  const box = sceneBounds();
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.05;
  camera.near = distance / 100;
  camera.far = distance * 100;
  const d = new THREE.Vector3(...direction).normalize();
  camera.position.copy(centre).add(d.clone().multiplyScalar(distance));
  // Straight up or down: any up that is not along the view.
  camera.up.set(0, 1, 0);
  if (Math.abs(d.y) > 0.999) camera.up.set(0, 0, -Math.sign(d.y));
  controls.target.copy(centre);
  camera.lookAt(centre);
  camera.updateProjectionMatrix();
  controls.update();
  render();
}

async function fetchBinary(url) {
  const response = await fetch(url);
  if (!response.ok) {
    throw new Error(`${url}: ${response.status} ${await response.text()}`);
  }
  return response.arrayBuffer();
}

function checkMagic(view, magic, url) {
  const text = String.fromCharCode(...new Uint8Array(view.buffer, view.byteOffset, 4));
  if (text !== magic || view.getUint32(4, true) !== 1) {
    throw new Error(`${url}: not a pointform ${magic} answer of version 1`);
  }
}

// /api/layer/<k>/level/<i>: "PFLV", u32 version, level, first vertex, new vertices, faces; then
// float32 xyz of the new vertices and uint32 abc of every face of the level (little-endian).
function parseLevel(buffer, url) {
  const view = new DataView(buffer);
  checkMagic(view, 'PFLV', url);
  const level = view.getUint32(8, true);
  const first = view.getUint32(12, true);
  const count = view.getUint32(16, true);
  const faces = view.getUint32(20, true);
  if (buffer.byteLength !== 24 + 12 * count + 12 * faces) {
    throw new Error(`${url}: ${buffer.byteLength} bytes, expected ${24 + 12 * count + 12 * faces}`);
  }
  return {
    level, first, count,
    positions: new Float32Array(buffer, 24, 3 * count),
    indices: new Uint32Array(buffer, 24 + 12 * count, 3 * faces),
  };
}

// /api/layer/<k>/distance/<i>: "PFDS", u32 version, level, vertices; float64 Hausdorff and mean
// distance from the samples to the level, float64 largest vertex distance; float32 per vertex.
function parseDistances(buffer, url) {
  const view = new DataView(buffer);
  checkMagic(view, 'PFDS', url);
  const count = view.getUint32(12, true);
  if (buffer.byteLength !== 40 + 4 * count) {
    throw new Error(`${url}: ${buffer.byteLength} bytes, expected ${40 + 4 * count}`);
  }
  return {
    hausdorff: view.getFloat64(16, true),
    mean: view.getFloat64(24, true),
    largest: view.getFloat64(32, true),
    perVertex: new Float32Array(buffer, 40, count),
  };
}

function formatDistance(d) {
  return d === undefined || d === null ? '' : d.toPrecision(3);
}

function updateFigures() {
  const rows = [];
  if (samples) {
    rows.push(`<tr><td colspan="4">samples: ${samples.info.points.toLocaleString('en')} points</td></tr>`);
  }
  if (active) {
    rows.push('<tr><th>level</th><th>faces</th><th>vertices</th>' +
      '<th title="one-sided Hausdorff distance from the samples: from the reconstruction report, or measured (*)">Hausdorff</th></tr>');
    const report = active.info.report ? active.info.report.levels : [];
    for (const l of active.info.levels) {
      const cls = [l.level === active.shown ? 'current' : '', active.levels[l.level] ? '' : 'pending'].join(' ');
      const fromReport = report[l.level] && report[l.level].hausdorff;
      const measured = active.distances[l.level] && active.distances[l.level].hausdorff;
      const h = fromReport !== undefined ? formatDistance(fromReport)
        : measured !== undefined ? `${formatDistance(measured)}*` : '';
      rows.push(`<tr class="${cls}"><td>${l.level}</td><td>${l.faces.toLocaleString('en')}</td>` +
        `<td>${l.vertices.toLocaleString('en')}</td><td>${h}</td></tr>`);
    }
  }
  figures.innerHTML = rows.join('');
}

function updateLayerList() {
  layerList.innerHTML = '';
  for (const layer of layers) {
    const label = document.createElement('label');
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = layer.group.visible;
    box.addEventListener('change', () => { layer.group.visible = box.checked; render(); });
    label.append(box, ` ${layer.info.file} (${layer.info.kind}${layer === active ? ', slider' : ''})`);
    if (layer.info.kind !== 'points' && layer !== active) {
      label.title = 'double-click: let the level slider act on this layer';
      label.addEventListener('dblclick', () => makeActive(layer));
    }
    layerList.append(label);
  }
}

/** A blue-to-red ramp: 0 at the samples, 1 at `scale` and beyond. */
function ramp(t, out, k) {
  const x = Math.min(Math.max(t, 0), 1);
  out[k] = Math.min(1, 2 * x);
  out[k + 1] = 1 - Math.abs(2 * x - 1) * 0.8;
  out[k + 2] = Math.min(1, 2 * (1 - x));
}

async function loadDistances(layer, i) {
  if (!samples) return null;
  if (!layer.distances[i]) {
    const url = `/api/layer/${layer.info.id}/distance/${i}`;
    layer.distances[i] = parseDistances(await fetchBinary(url), url);
  }
  return layer.distances[i];
}

async function applyColours() {
  const layer = active;
  if (!layer || layer.shown < 0) return;
  const entry = layer.levels[layer.shown];
  if (colorByDistance && samples) {
    const d = await loadDistances(layer, layer.shown);
    if (!entry.geometry.getAttribute('color')) {
      // One scale for every level of the layer: the coarsest level's largest distance.
      const scale = Math.max((await loadDistances(layer, 0)).largest, 1e-12);
      const colours = new Float32Array(3 * d.perVertex.length);
      for (let v = 0; v < d.perVertex.length; ++v) ramp(d.perVertex[v] / scale, colours, 3 * v);
      entry.geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
      layer.scale = scale;
    }
    layer.object.material = distanceMaterial;
    legend.hidden = false;
    legend.textContent = `distance to the nearest sample: blue 0, red ≥ ${formatDistance(layer.scale)}`;
  } else {
    layer.object.material = surfaceMaterial;
    legend.hidden = true;
  }
  updateFigures();
  render();
}

function showLevel(layer, i) {
  const entry = layer.levels[i];
  if (!entry) {
    throw new RangeError(`level ${i} is not loaded (${layer.levels.filter(Boolean).length} of ${layer.info.levels.length} arrived)`);
  }
  if (!layer.object) {
    layer.object = new THREE.Mesh(entry.geometry, surfaceMaterial);
    layer.group.add(layer.object);
  } else {
    layer.object.geometry = entry.geometry;
  }
  layer.shown = i;
  if (layer === active) {
    slider.value = String(i);
    sliderValue.textContent = String(i);
    updateFigures();
  }
  render();
  if (layer === active && colorByDistance) applyColours().catch(report);
}

function makeActive(layer) {
  if (baseOverlay) {
    baseOverlay.removeFromParent();
    baseOverlay = null;
  }
  if (active && active.object) active.object.material = surfaceMaterial;
  active = layer;
  slider.max = String(layer.info.levels.length - 1);
  $('level-controls').hidden = false;
  if (layer.shown >= 0) showLevel(layer, layer.shown);
  if (baseBox.checked) setBaseOverlay(true);
  updateLayerList();
  updateFigures();
}

function setBaseOverlay(on) {
  if (on && !baseOverlay && active && active.levels[0]) {
    baseOverlay = new THREE.LineSegments(new THREE.WireframeGeometry(active.levels[0].geometry), baseMaterial);
    active.group.add(baseOverlay);
  }
  if (baseOverlay) baseOverlay.visible = on;
  render();
}

async function loadLevels(layer) {
  const n = layer.info.levels.length;
  layer.positions = new Float32Array(3 * layer.info.levels[n - 1].vertices);
  for (let i = 0; i < n; ++i) {
    statusLine.textContent = `${layer.info.file}: level ${i} of ${n - 1}…`;
    const url = `/api/layer/${layer.info.id}/level/${i}`;
    const part = parseLevel(await fetchBinary(url), url);
    layer.positions.set(part.positions, 3 * part.first);
    const vertices = part.first + part.count;
    const geometry = new THREE.BufferGeometry();
    // A view of the prefix: the vertices of coarser levels are never moved or copied.
    geometry.setAttribute('position', new THREE.BufferAttribute(layer.positions.subarray(0, 3 * vertices), 3));
    geometry.setIndex(new THREE.BufferAttribute(part.indices, 1));
    geometry.computeVertexNormals();
    layer.levels[i] = { geometry, faces: part.indices.length / 3, vertices };
    if (layer !== active || followStream || layer.shown < 0) showLevel(layer, i);
    else updateFigures();
  }
  statusLine.textContent = `${layer.info.file}: ${n} level${n === 1 ? '' : 's'}`;
}

// /api/layer/<k>/points: "PFPT", u32 version, count, flags (1 normals, 2 colours); float32 xyz,
// then float32 normals if any, then uint8 rgb if any.
async function loadPoints(layer) {
  const url = `/api/layer/${layer.info.id}/points`;
  const buffer = await fetchBinary(url);
  const view = new DataView(buffer);
  checkMagic(view, 'PFPT', url);
  const count = view.getUint32(8, true);
  const flags = view.getUint32(12, true);
  const hasNormals = (flags & 1) !== 0;
  const hasColors = (flags & 2) !== 0;
  const expected = 16 + 12 * count + (hasNormals ? 12 * count : 0) + (hasColors ? 3 * count : 0);
  if (buffer.byteLength !== expected) {
    throw new Error(`${url}: ${buffer.byteLength} bytes, expected ${expected}`);
  }
  const geometry = new THREE.BufferGeometry();
  layer.positions = new Float32Array(buffer, 16, 3 * count);
  geometry.setAttribute('position', new THREE.BufferAttribute(layer.positions, 3));
  const offset = 16 + 12 * count;
  const material = new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, color: 0x4a6a9a });
  if (hasColors) {
    const rgb = new Uint8Array(buffer, offset + (hasNormals ? 12 * count : 0), 3 * count);
    geometry.setAttribute('color', new THREE.BufferAttribute(rgb, 3, true));
    material.vertexColors = true;
    material.color.set(0xffffff);
  } else if (hasNormals) {
    const normals = new Float32Array(buffer, offset, 3 * count);
    const colours = new Float32Array(3 * count);
    for (let k = 0; k < 3 * count; ++k) colours[k] = 0.5 + 0.5 * normals[k];
    geometry.setAttribute('color', new THREE.BufferAttribute(colours, 3));
    material.vertexColors = true;
    material.color.set(0xffffff);
  }
  layer.object = new THREE.Points(geometry, material);
  layer.group.add(layer.object);
  layer.description = `${count.toLocaleString('en')} points` +
    (hasColors ? ', coloured by their colours' : hasNormals ? ', coloured by their normals' : '');
  statusLine.textContent = `${layer.info.file}: ${layer.description}`;
  render();
}

/** Adds a layer of the server's list and loads it. */
async function addLayer(layerInfo) {
  const group = new THREE.Group();
  group.position.set(...layerInfo.origin.map((o, k) => o - sceneOrigin[k]));
  scene.add(group);
  const layer = { info: layerInfo, group, levels: [], distances: [], shown: -1, object: null };
  layers.push(layer);
  if (layerInfo.kind === 'points') {
    if (!samples && info.samples === layerInfo.id) samples = layer;
    updateLayerList();
    await loadPoints(layer);
  } else {
    if (!active || layerInfo.source === 'reconstruction') makeActive(layer);
    updateLayerList();
    await loadLevels(layer);
  }
  updateFigures();
  return layer;
}

// ------------------------------------------------------------------------------------------
// The picked base mesh (Fig. 6).

const picked = new PickedBaseMesh();
let selection = [];   // base vertices chosen for the next triangle (up to three)
let pickOverlay = null;
let pickMessage = '';
let job = null;       // the last reconstruction's status from the server

/** The world position of sample s (the samples' origin plus its float position). */
function samplePosition(s) {
  const p = samples.positions;
  return [0, 1, 2].map((k) => samples.info.origin[k] + p[3 * s + k]);
}

/**
 * The sample under the screen point (x, y) in CSS pixels from the canvas's top-left corner:
 * of the samples drawn within 6 pixels of it, the nearest to the camera; null if none.
 */
function pickSample(x, y) {
  if (!samples || !samples.group.visible) return null;
  samples.object.updateMatrixWorld();
  camera.updateMatrixWorld();
  const m = new THREE.Matrix4().multiplyMatrices(camera.projectionMatrix, camera.matrixWorldInverse)
    .multiply(samples.object.matrixWorld).elements;
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  const radius = 6;
  const p = samples.positions;
  let best = null;
  let bestDepth = Infinity;
  for (let s = 0; s < p.length / 3; ++s) {
    const px = p[3 * s];
    const py = p[3 * s + 1];
    const pz = p[3 * s + 2];
    const cw = m[3] * px + m[7] * py + m[11] * pz + m[15];
    if (cw <= 0) continue;
    const sx = ((m[0] * px + m[4] * py + m[8] * pz + m[12]) / cw + 1) / 2 * w;
    const sy = (1 - (m[1] * px + m[5] * py + m[9] * pz + m[13]) / cw) / 2 * h;
    if (Math.abs(sx - x) > radius || Math.abs(sy - y) > radius) continue;
    if ((sx - x) ** 2 + (sy - y) ** 2 > radius * radius) continue;
    const depth = (m[2] * px + m[6] * py + m[10] * pz + m[14]) / cw;
    if (depth < bestDepth) {
      bestDepth = depth;
      best = s;
    }
  }
  return best;
}

/** Sample s on the screen: x and y as fractions of the canvas (from its top-left), and depth. */
function screenOf(s) {
  samples.object.updateMatrixWorld();
  camera.updateMatrixWorld();
  const v = new THREE.Vector3(...samples.positions.subarray(3 * s, 3 * s + 3));
  v.applyMatrix4(samples.object.matrixWorld).project(camera);
  return [(v.x + 1) / 2, (1 - v.y) / 2, v.z];
}

function drawPicked() {
  if (pickOverlay) pickOverlay.removeFromParent();
  pickOverlay = null;
  if (!samples) return;
  const group = new THREE.Group();
  const at = (s) => samples.positions.subarray(3 * s, 3 * s + 3);
  if (picked.vertices.length > 0) {
    const g = new THREE.BufferGeometry();
    const xyz = new Float32Array(3 * picked.vertices.length);
    const rgb = new Float32Array(3 * picked.vertices.length);
    picked.vertices.forEach((s, i) => {
      xyz.set(at(s), 3 * i);
      rgb.set(selection.includes(s) ? [0.85, 0.1, 0.1] : [0.95, 0.55, 0.1], 3 * i);
    });
    g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    g.setAttribute('color', new THREE.BufferAttribute(rgb, 3));
    group.add(new THREE.Points(g, new THREE.PointsMaterial({
      size: 9, sizeAttenuation: false, vertexColors: true, depthTest: false })));
  }
  if (picked.triangles.length > 0) {
    const g = new THREE.BufferGeometry();
    const xyz = new Float32Array(9 * picked.triangles.length);
    picked.triangles.forEach((t, f) => t.forEach((s, k) => xyz.set(at(s), 9 * f + 3 * k)));
    g.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    g.computeVertexNormals();
    group.add(new THREE.Mesh(g, new THREE.MeshPhongMaterial({
      color: 0xf0a040, transparent: true, opacity: 0.55, side: THREE.DoubleSide })));
    const check = picked.check();
    const bad = new Set(check.badEdges.map(([a, b]) => `${Math.min(a, b)},${Math.max(a, b)}`));
    const edges = [];
    const colours = [];
    const done = new Set();
    for (const t of picked.triangles) {
      for (let k = 0; k < 3; ++k) {
        const a = t[k];
        const b = t[(k + 1) % 3];
        const key = `${Math.min(a, b)},${Math.max(a, b)}`;
        if (done.has(key)) continue;
        done.add(key);
        edges.push(...at(a), ...at(b));
        const c = bad.has(key) ? [0.9, 0, 0] : [0.55, 0.25, 0.05];
        colours.push(...c, ...c);
      }
    }
    const eg = new THREE.BufferGeometry();
    eg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(edges), 3));
    eg.setAttribute('color', new THREE.BufferAttribute(new Float32Array(colours), 3));
    group.add(new THREE.LineSegments(eg, new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false })));
  }
  group.renderOrder = 10;
  // Beside the samples, not in their group: it stays visible when the samples are hidden.
  group.position.copy(samples.group.position);
  scene.add(group);
  pickOverlay = group;
}

function updatePicked() {
  const check = picked.check();
  $('pick-figures').textContent =
    `${check.vertices} vertices, ${check.triangles} triangles, ${check.edges} edges; ` +
    `${check.closed ? 'closed' : `${check.boundaryEdges} boundary edges`}, ` +
    `${check.components} component${check.components === 1 ? '' : 's'}, Euler characteristic ${check.euler}` +
    (selection.length > 0 ? `; selected: ${selection.join(', ')}` : '');
  const checks = $('pick-checks');
  checks.innerHTML = '';
  const line = (ok, text) => {
    const li = document.createElement('li');
    li.className = ok ? 'ok' : 'problem';
    li.textContent = text;
    checks.append(li);
  };
  if (check.triangles > 0 && check.manifold) line(true, 'manifold');
  if (check.triangles > 0 && check.orientable) line(true, 'oriented consistently');
  for (const p of check.problems) line(false, p);
  $('pick-message').textContent = pickMessage;
  $('reconstruct').disabled = !check.ok || (job && job.state === 'running');
  $('undo').disabled = picked.history.length === 0;
  $('save-base').disabled = picked.triangles.length === 0;
  drawPicked();
  render();
  return check;
}

/** Joins three base vertices, first turned to face the camera (counter-clockwise on screen). */
function joinTriangle(a, b, c) {
  const [pa, pb, pc] = [a, b, c].map(screenOf);
  const cross = (pb[0] - pa[0]) * (pc[1] - pa[1]) - (pb[1] - pa[1]) * (pc[0] - pa[0]);
  // Screen y grows downwards: counter-clockwise on screen is a negative cross product here.
  const t = cross <= 0 ? [a, b, c] : [a, c, b];
  picked.join(...t);
}

/** The distance from the camera to sample s. */
function cameraDistance(s) {
  const v = new THREE.Vector3(...samples.positions.subarray(3 * s, 3 * s + 3));
  return v.applyMatrix4(samples.object.matrixWorld).distanceTo(camera.position);
}

/** The base vertex drawn within 8 pixels of (x, y), the nearest to the camera, or null. */
function pickBaseVertex(x, y) {
  let best = null;
  let bestDepth = Infinity;
  for (const s of picked.vertices) {
    const [sx, sy, depth] = screenOf(s);
    const dx = sx * canvas.clientWidth - x;
    const dy = sy * canvas.clientHeight - y;
    if (dx * dx + dy * dy <= 64 && depth < bestDepth) {
      bestDepth = depth;
      best = s;
    }
  }
  return best;
}

/**
 * A click on the page in picking mode: a base vertex under the pointer is selected (or
 * unselected), else the sample under it is added as a base vertex and selected; three selected
 * vertices are joined into a triangle.
 */
function pickAt(x, y) {
  // A base vertex wins unless a sample is drawn in front of it (base vertices are drawn over
  // everything, so one on the far side shows through).
  const vertex = pickBaseVertex(x, y);
  const sample = pickSample(x, y);
  const tolerance = 0.02 * sceneBounds().getSize(new THREE.Vector3()).length();
  const s = vertex !== null && (sample === null ||
    cameraDistance(vertex) <= cameraDistance(sample) + tolerance) ? vertex : sample;
  pickMessage = '';
  if (s === null) {
    pickMessage = 'no sample there';
  } else {
    if (!picked.hasVertex(s)) picked.addVertex(s);
    if (selection.includes(s)) selection = selection.filter((v) => v !== s);
    else selection.push(s);
    if (selection.length === 3) {
      try {
        joinTriangle(...selection);
      } catch (error) {
        pickMessage = error.message;
      }
      selection = [];
    }
  }
  updatePicked();
  return s;
}

function undo() {
  selection = [];
  pickMessage = '';
  const what = picked.undo();
  updatePicked();
  return what;
}

function saveBaseMesh() {
  const text = picked.toObj(samplePosition, samples.info.file);
  const link = document.createElement('a');
  link.download = `${samples.info.file.replace(/\.[^.]*$/, '')}_base_mesh.obj`;
  link.href = URL.createObjectURL(new Blob([text], { type: 'text/plain' }));
  link.click();
  setTimeout(() => URL.revokeObjectURL(link.href), 10000);
  return text;
}

function showJob(status) {
  job = status;
  const line = $('job');
  line.className = status.state === 'failed' ? 'problem' : '';
  if (status.state === 'running') {
    line.textContent = `reconstructing: ${status.stage} ${Math.round(100 * status.fraction)}%`;
  } else if (status.state === 'failed') {
    line.textContent = `refused: ${status.message}`;
  } else if (status.state === 'done') {
    line.textContent = `reconstructed in ${status.seconds.toFixed(1)} s: ` +
      `${status.report.levels.length} levels (stop: ${status.report.stop})`;
  } else {
    line.textContent = '';
  }
  updatePicked();
}

/**
 * Sends the picked base mesh to the server and waits: on success the new hierarchy is loaded as
 * a layer (levels streamed coarse to fine) and the status is returned; a refusal (the server's
 * reason shown on the page) is returned too. `force` sends even when the page's checks fail.
 */
async function reconstruct(force = false) {
  const check = picked.check();
  if (!check.ok && !force) throw new Error(check.problems.join('; '));
  const response = await fetch('/api/reconstruct', { method: 'POST', body: picked.request() });
  if (!response.ok) {
    const text = (await response.text()).trim();
    showJob({ state: 'failed', message: text });
    return job;
  }
  showJob(await response.json());
  while (job.state === 'running') {
    await new Promise((resolve) => { setTimeout(resolve, 150); });
    const r = await fetch('/api/reconstruct');
    showJob(await r.json());
  }
  if (job.state === 'done') {
    const fresh = await (await fetch('/api/info')).json();
    info.layers = fresh.layers;
    followStream = true;
    const layerInfo = fresh.layers[job.layer];
    // The new surface replaces the others on screen (their boxes in the list bring them back).
    for (const l of layers) if (l.info.kind !== 'points') l.group.visible = false;
    await addLayer(layerInfo);
    updateLayerList();
  }
  return job;
}

// ------------------------------------------------------------------------------------------

function exportPicture() {
  render();
  const link = document.createElement('a');
  const stem = info ? info.layers[0].file.replace(/\.[^.]*$/, '') : 'pointform';
  link.download = active && active.shown >= 0 ? `${stem}_level${active.shown}.png` : `${stem}.png`;
  link.href = canvas.toDataURL('image/png');
  link.click();
}

function report(error) {
  statusLine.textContent = `error: ${error.message}`;
  console.error(error);
}

// The test hook (tests/view/viewer_e2e.mjs drives it).
window.pointform = {
  /** Levels of the active surface layer (0 without one). */
  levelCount: () => (active ? active.info.levels.length : 0),
  /** Levels of the active layer that have arrived so far. */
  loadedLevels: () => (active ? active.levels.filter(Boolean).length : 0),
  /** Shows level i of the active layer (it must have arrived); stops following the stream. */
  setLevel: (i) => { followStream = false; showLevel(active, i); return active.shown; },
  /** The level drawn now (-1 without a surface). */
  level: () => (active ? active.shown : -1),
  /** Triangles of the active layer drawn now. */
  faceCount: () => (active && active.object ? active.object.geometry.index.count / 3 : 0),
  /** Resolves (to the level count) once every layer has arrived and been drawn; rejects if
   *  loading failed. */
  ready: () => readyPromise,
  isReady: () => allArrived,
  /** Shows or hides layer `id`. */
  setLayerVisible: (id, on) => { layers[id].group.visible = on; updateLayerList(); render(); },
  /** The layers: file, kind, levels, source ("file" or "reconstruction"). */
  layers: () => layers.map((l) => ({ id: l.info.id, file: l.info.file, kind: l.info.kind,
    levels: l.info.levels.length, source: l.info.source })),
  setWireframe: (on) => { wireframeBox.checked = on; surfaceMaterial.wireframe = on; distanceMaterial.wireframe = on; render(); },
  setBaseOverlay: (on) => { baseBox.checked = on; setBaseOverlay(on); },
  /** Colours the active layer by the distance of its vertices to the nearest sample. */
  setColorByDistance: async (on) => { distanceBox.checked = on; colorByDistance = on; await applyColours(); },
  /** The one-sided Hausdorff distance from the samples to level i of the active layer, measured
   *  by the server (GET /api/layer/<k>/distance/<i>). */
  hausdorff: async (i) => (await loadDistances(active, i)).hausdorff,
  /** The active layer's per-level figures from the reconstruction report (null for a file). */
  report: () => (active && active.info.report ? active.info.report : null),
  exportPicture,
  /** Looks at the scene from direction [x, y, z]. */
  setView: (direction) => frame(direction),
  /** The sample drawn under (x, y) (CSS pixels from the canvas's top-left), or null. */
  pickSample,
  /** Where the centre of the scene's box is drawn now: [x, y] in CSS pixels. */
  sceneCentreOnScreen: () => {
    const v = sceneBounds().getCenter(new THREE.Vector3()).project(camera);
    return [(v.x + 1) / 2 * canvas.clientWidth, (1 - v.y) / 2 * canvas.clientHeight];
  },
  /** Where sample s is drawn now: [x, y] in CSS pixels from the canvas's top-left. */
  sampleScreenPosition: (s) => { const [x, y] = screenOf(s); return [x * canvas.clientWidth, y * canvas.clientHeight]; },
  /** A click in picking mode at (x, y): the picked sample or null. */
  pick: (x, y) => pickAt(x, y),
  /** Adds sample s as a base vertex (as a click on it would). */
  addVertex: (s) => { const added = picked.addVertex(s); updatePicked(); return added; },
  /** Joins three base vertices into a triangle (oriented to agree with its neighbours). */
  joinTriangle: (a, b, c) => { joinTriangle(a, b, c); updatePicked(); return picked.triangles.length; },
  undo,
  /** The picked base mesh: its triangles and the live checks. */
  baseMesh: () => ({ vertices: [...picked.vertices], triangles: picked.triangles.map((t) => [...t]),
    check: picked.check(), shownChecks: [...document.querySelectorAll('#pick-checks li')].map((li) => li.textContent) }),
  /** The text shown for the last reconstruction (its progress, result or refusal). */
  jobText: () => $('job').textContent,
  /** The picked base mesh as the OBJ `reconstruct --base-mesh` reads (also downloaded). */
  saveBaseMesh,
  reconstruct,
};

slider.addEventListener('input', () => {
  const i = Number(slider.value);
  if (active && active.levels[i]) {
    followStream = false;
    showLevel(active, i);
  } else if (active) {
    slider.value = String(active.shown);
  }
});
wireframeBox.addEventListener('change', () => window.pointform.setWireframe(wireframeBox.checked));
baseBox.addEventListener('change', () => setBaseOverlay(baseBox.checked));
distanceBox.addEventListener('change', () => window.pointform.setColorByDistance(distanceBox.checked).catch(report));
$('export').addEventListener('click', exportPicture);
$('undo').addEventListener('click', undo);
$('clear').addEventListener('click', () => { picked.clear(); selection = []; pickMessage = ''; updatePicked(); });
$('save-base').addEventListener('click', saveBaseMesh);
$('reconstruct').addEventListener('click', () => reconstruct().catch(report));
controls.addEventListener('change', render);
window.addEventListener('resize', resize);
window.addEventListener('keydown', (event) => {
  if ((event.ctrlKey || event.metaKey) && event.key === 'z') {
    event.preventDefault();
    undo();
  }
});

// A click (not a drag of the orbit camera) in picking mode picks a sample.
let down = null;
canvas.addEventListener('pointerdown', (event) => { down = { x: event.clientX, y: event.clientY, t: event.timeStamp }; });
canvas.addEventListener('pointerup', (event) => {
  if (!down || !$('pick-mode').checked) return;
  const moved = Math.hypot(event.clientX - down.x, event.clientY - down.y);
  if (moved < 4 && event.timeStamp - down.t < 600) {
    const r = canvas.getBoundingClientRect();
    pickAt(event.clientX - r.left, event.clientY - r.top);
  }
  down = null;
});

async function main() {
  const response = await fetch('/api/info');
  if (!response.ok) throw new Error(`/api/info: ${response.status}`);
  info = await response.json();
  sceneOrigin = info.layers[0].origin;
  const names = info.layers.map((l) => l.file).join(', ');
  document.title = `${names} - pointform view`;
  $('title').textContent = names;
  frame();
  resize();
  distanceBox.disabled = info.samples === null;
  distanceBox.parentElement.title = info.samples === null
    ? 'name a point cloud on the command line to measure distances to it' : '';
  $('pick-panel').hidden = info.samples === null;
  for (const layerInfo of info.layers) await addLayer(layerInfo);
  if (samples) updatePicked();
  const described = layers.map((l) => (l.info.kind === 'points' ? `${l.info.file}: ${l.description}`
    : `${l.info.file}: ${l.info.levels.length} level${l.info.levels.length === 1 ? '' : 's'}`));
  statusLine.textContent = described.join('; ');
  allArrived = true;
  resolveReady(active ? active.info.levels.length : 0);
}

main().catch((error) => {
  report(error);
  readyPromise.catch(() => {});
  resolveReady(Promise.reject(error));
});
