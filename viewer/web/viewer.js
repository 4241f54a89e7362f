// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors
//
// The page of `pointform view`: reads /api/info, then streams a hierarchy's levels coarse to
// fine from /api/level/<i> (each level's vertices are a prefix of the next, so every answer
// only carries the vertices new at that level and is appended), or a point cloud from
// /api/points. Binary layouts: docs/viewer.md. Test hook: window.pointform.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const canvas = document.getElementById('view');
const statusLine = document.getElementById('status');
const slider = document.getElementById('level');
const sliderValue = document.getElementById('level-value');
const wireframeBox = document.getElementById('wireframe');
const baseBox = document.getElementById('base-overlay');
const figures = document.getElementById('figures');

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
const baseMaterial = new THREE.LineBasicMaterial({ color: 0xd04a1c });

let info = null;
const levels = []; // per level: { geometry, faces, vertices } once it has arrived
let shownLevel = -1;
let followStream = true; // show each level as it arrives until the user picks one
let surface = null;      // the THREE.Mesh or THREE.Points drawn now
let baseOverlay = null;
let positions = null;    // every vertex of the finest level, filled level by level
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
  camera.updateProjectionMatrix();
  render();
}

function frame(box) {
  const min = new THREE.Vector3(...box.min);
  const max = new THREE.Vector3(...box.max);
  const centre = min.clone().add(max).multiplyScalar(0.5);
  const radius = Math.max(max.clone().sub(min).length() / 2, 1e-9);
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.05;
  camera.near = distance / 100;
  camera.far = distance * 100;
  camera.position.copy(centre).add(new THREE.Vector3(0.35, 0.25, 1).normalize().multiplyScalar(distance));
  controls.target.copy(centre);
  camera.updateProjectionMatrix();
  controls.update();
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

// /api/level/<i>: "PFLV", u32 version, level, first vertex, new vertices, faces; then float32
// xyz of the new vertices and uint32 abc of every face of the level (little-endian).
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

function updateFigures() {
  const rows = ['<tr><th>level</th><th>faces</th><th>vertices</th></tr>'];
  if (info.kind === 'points') {
    rows.push(`<tr><td>points</td><td></td><td>${info.points.toLocaleString('en')}</td></tr>`);
  }
  for (const l of info.levels) {
    const cls = [l.level === shownLevel ? 'current' : '', levels[l.level] ? '' : 'pending'].join(' ');
    rows.push(`<tr class="${cls}"><td>${l.level}</td><td>${l.faces.toLocaleString('en')}</td>` +
      `<td>${l.vertices.toLocaleString('en')}</td></tr>`);
  }
  figures.innerHTML = rows.join('');
}

function showLevel(i) {
  const entry = levels[i];
  if (!entry) {
    throw new RangeError(`level ${i} is not loaded (${levels.length} of ${info.levels.length} arrived)`);
  }
  if (!surface) {
    surface = new THREE.Mesh(entry.geometry, surfaceMaterial);
    scene.add(surface);
  } else {
    surface.geometry = entry.geometry;
  }
  shownLevel = i;
  slider.value = String(i);
  sliderValue.textContent = String(i);
  updateFigures();
  render();
}

function setBaseOverlay(on) {
  if (on && !baseOverlay && levels[0]) {
    baseOverlay = new THREE.LineSegments(new THREE.WireframeGeometry(levels[0].geometry), baseMaterial);
    scene.add(baseOverlay);
  }
  if (baseOverlay) baseOverlay.visible = on;
  render();
}

async function loadLevels() {
  const n = info.levels.length;
  positions = new Float32Array(3 * info.levels[n - 1].vertices);
  slider.max = String(n - 1);
  document.getElementById('level-controls').hidden = false;
  for (let i = 0; i < n; ++i) {
    statusLine.textContent = `${info.kind} ${info.file}: level ${i} of ${n - 1}…`;
    const url = `/api/level/${i}`;
    const part = parseLevel(await fetchBinary(url), url);
    positions.set(part.positions, 3 * part.first);
    const vertices = part.first + part.count;
    const geometry = new THREE.BufferGeometry();
    // A view of the prefix: the vertices of coarser levels are never moved or copied.
    geometry.setAttribute('position', new THREE.BufferAttribute(positions.subarray(0, 3 * vertices), 3));
    geometry.setIndex(new THREE.BufferAttribute(part.indices, 1));
    geometry.computeVertexNormals();
    levels[i] = { geometry, faces: part.indices.length / 3, vertices };
    if (followStream) showLevel(i);
    else updateFigures();
  }
  statusLine.textContent = `${info.kind} ${info.file}: ${n} level${n === 1 ? '' : 's'}`;
}

// /api/points: "PFPT", u32 version, count, flags (1 normals, 2 colours); float32 xyz, then
// float32 normals if any, then uint8 rgb if any.
async function loadPoints() {
  const url = '/api/points';
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
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(buffer, 16, 3 * count), 3));
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
  surface = new THREE.Points(geometry, material);
  scene.add(surface);
  statusLine.textContent = `points ${info.file}: ${count.toLocaleString('en')}` +
    (hasColors ? ', coloured by their colours' : hasNormals ? ', coloured by their normals' : '');
  updateFigures();
  render();
}

function exportPicture() {
  render();
  const link = document.createElement('a');
  const stem = info ? info.file.replace(/\.[^.]*$/, '') : 'pointform';
  link.download = shownLevel >= 0 ? `${stem}_level${shownLevel}.png` : `${stem}.png`;
  link.href = canvas.toDataURL('image/png');
  link.click();
}

// The test hook (tests/view/viewer_e2e.mjs drives it).
window.pointform = {
  /** Levels the file has (0 for a point cloud, 1 for a mesh). */
  levelCount: () => (info ? info.levels.length : 0),
  /** Levels that have arrived so far. */
  loadedLevels: () => levels.filter(Boolean).length,
  /** Shows level i (it must have arrived) and returns it; stops following the stream. */
  setLevel: (i) => { followStream = false; showLevel(i); return shownLevel; },
  /** The level drawn now (-1 for a point cloud). */
  level: () => shownLevel,
  /** Triangles drawn now. */
  faceCount: () => (surface && surface.isMesh ? surface.geometry.index.count / 3 : 0),
  /** Resolves (to the level count) once every level or the points have arrived and been drawn;
   *  rejects if loading failed. */
  ready: () => readyPromise,
  /** Whether everything has arrived. */
  isReady: () => allArrived,
  setWireframe: (on) => { wireframeBox.checked = on; surfaceMaterial.wireframe = on; render(); },
  setBaseOverlay: (on) => { baseBox.checked = on; setBaseOverlay(on); },
  exportPicture,
};

slider.addEventListener('input', () => {
  const i = Number(slider.value);
  if (levels[i]) {
    followStream = false;
    showLevel(i);
  } else {
    slider.value = String(shownLevel);
  }
});
wireframeBox.addEventListener('change', () => { surfaceMaterial.wireframe = wireframeBox.checked; render(); });
baseBox.addEventListener('change', () => setBaseOverlay(baseBox.checked));
document.getElementById('export').addEventListener('click', exportPicture);
controls.addEventListener('change', render);
window.addEventListener('resize', resize);

async function main() {
  const response = await fetch('/api/info');
  if (!response.ok) throw new Error(`/api/info: ${response.status}`);
  info = await response.json();
  document.title = `${info.file} - pointform view`;
  document.getElementById('title').textContent = info.file;
  frame(info.bounding_box);
  resize();
  updateFigures();
  if (info.kind === 'points') await loadPoints();
  else await loadLevels();
  allArrived = true;
  resolveReady(info.levels.length);
}

main().catch((error) => {
  statusLine.textContent = `error: ${error.message}`;
  console.error(error);
  readyPromise.catch(() => {});
  resolveReady(Promise.reject(error));
});
