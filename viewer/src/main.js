// graspsim's browser viewer of one scene (/view/<scene>). Geometry is fetched once (scene.json) and again only
// when the snapshots' body list changes; after that only poses (/poses) and tactile readings (/tactile) flow,
// as Server-Sent Events. Read-only: the page never changes the scene.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { ContactOverlay } from './contacts.js';
import { buildBodies, buildPad, decodeBase64 } from './geometry.js';
import { buildGraspGhosts } from './grasps.js';
import { ResultOverlays } from './overlays.js';
import { TactilePanels } from './tactile.js';

const sceneId = decodeURIComponent(location.pathname.split('/')[2] || '');
const base = `/view/${encodeURIComponent(sceneId)}`;
const query = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
$('scene-id').textContent = sceneId;
document.title = `graspsim · ${sceneId}`;

const kBackground = 0x1d2024;
const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(kBackground);
$('view').append(renderer.domElement);

const world = new THREE.Scene();
world.add(new THREE.HemisphereLight(0xffffff, 0x303030, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(1, -2, 3);
world.add(sun);
const camera = new THREE.PerspectiveCamera(45, 1, 0.001, 100);
camera.up.set(0, 0, 1);  // graspsim's world is z up
camera.position.set(0.6, -0.9, 0.6);
const controls = new OrbitControls(camera, renderer.domElement);
const grid = new THREE.GridHelper(2, 40, 0x555555, 0x333333);
grid.rotateX(Math.PI / 2);
world.add(grid, new THREE.AxesHelper(0.1));

// What the page knows, also read by the headless-browser tests (tests/python/test_viewer_browser.py).
const state = {
  ready: false, sceneFetches: 0, snapshots: 0, lastSnapshot: null, bodyIds: [], tactileReadings: 0, contacts: 0,
  bodies: new Map(), pads: null, error: null,
};

function resize() {
  const { clientWidth: w, clientHeight: h } = $('view');
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

// Frame the bodies that move (objects and robots; all bodies when only static ones exist) once, at the first
// load: the table is context, the grasp is what people look at.
function frameScene() {
  const box = new THREE.Box3();
  const groups = [...state.bodies.values()];
  const moving = groups.filter((group) => !group.userData.isStatic);
  for (const group of moving.length ? moving : groups) box.expandByObject(group);
  if (box.isEmpty()) return;
  const size = Math.max(0.3, 1.5 * box.getSize(new THREE.Vector3()).length());
  const centre = box.getCenter(new THREE.Vector3());
  controls.target.copy(centre);
  camera.position.copy(centre).add(new THREE.Vector3(0.7, -1.0, 0.7).multiplyScalar(size));
  controls.update();
}

async function loadScene() {
  const response = await fetch(`${base}/scene.json`);
  if (!response.ok) throw new Error((await response.json()).message);
  const scene = await response.json();
  state.sceneFetches += 1;
  for (const group of state.bodies.values()) world.remove(group);
  state.bodies = buildBodies(scene);
  for (const group of state.bodies.values()) world.add(group);
  state.bodyIds = [...state.bodies.keys()];
  const arrays = scene.tactile_arrays || [];
  if (arrays.length && !state.pads) {
    $('tactile-section').hidden = false;
    state.pads = new TactilePanels($('tactile'), arrays);
    startTactile();
  }
  for (const array of state.pads ? arrays : []) {
    const canvas = state.pads.canvasFor(array.id);
    const body = state.bodies.get(array.body_id);
    if (canvas && body) body.add(buildPad(array, canvas));
  }
  return scene;
}

// Simulation time and rate from the snapshots: simulated seconds per wall second, over the last second.
const rateWindow = [];
function showTime(snapshot) {
  const now = performance.now() / 1000;
  rateWindow.push([now, snapshot.time]);
  while (rateWindow.length > 2 && rateWindow[0][0] < now - 1) rateWindow.shift();
  $('sim-time').textContent = snapshot.time.toFixed(3);
  if (rateWindow.length >= 2) {
    const [w0, t0] = rateWindow[0], [w1, t1] = rateWindow[rateWindow.length - 1];
    $('sim-rate').textContent = w1 > w0 ? ((t1 - t0) / (w1 - w0)).toFixed(2) : '–';
    $('snapshot-rate').textContent = w1 > w0 ? ((rateWindow.length - 1) / (w1 - w0)).toFixed(0) : '–';
  }
}

let snapshotIds = [];
let contactOverlay = null;
let reloading = null;
function applySnapshot(snapshot) {
  if (snapshot.body_ids) snapshotIds = snapshot.body_ids;
  const known = snapshotIds.length === state.bodyIds.length && snapshotIds.every((id, i) => state.bodies.has(id));
  if (!known && !reloading) {  // bodies added or removed: fetch the geometry again, then carry on
    reloading = loadScene().finally(() => { reloading = null; });
  }
  snapshotIds.forEach((id, i) => {
    const group = state.bodies.get(id);
    if (!group) return;
    const p = snapshot.poses.slice(7 * i, 7 * i + 7);
    group.position.set(p[0], p[1], p[2]);
    group.quaternion.set(p[4], p[5], p[6], p[3]);
  });
  if (contactOverlay && snapshot.contacts_f32 !== undefined) {
    contactOverlay.update(new Float32Array(decodeBase64(snapshot.contacts_f32)));
    state.contacts = contactOverlay.count;
  }
  state.snapshots += 1;
  state.lastSnapshot = { sequence: snapshot.sequence, revision: snapshot.revision, time: snapshot.time };
  showTime(snapshot);
}

function streamEvents(path, event, onData) {
  const source = new EventSource(`${base}/${path}`);
  source.addEventListener(event, (e) => onData(JSON.parse(e.data)));
  source.addEventListener('status', (e) => {
    const status = JSON.parse(e.data);
    // Streams end after max_seconds (OK) and EventSource reconnects by itself; an error is shown and final.
    if (status.code !== 0) {
      $('status').textContent = `${path}: ${status.status}: ${status.message}`;
      source.close();
    }
  });
  return source;
}

function startTactile() {
  streamEvents('tactile', 'reading', (reading) => {
    const pad = state.pads.update(reading);
    state.tactileReadings += 1;
    for (const group of state.bodies.values()) {
      group.traverse((o) => { if (o.userData.texture && pad) o.userData.texture.needsUpdate = true; });
    }
  });
}

async function loadGrasps(setId) {
  const response = await fetch(`${base}/grasps?set_id=${encodeURIComponent(setId)}`);
  if (!response.ok) throw new Error((await response.json()).message);
  const set = await response.json();
  // The set is in the object's frame: ghosts ride on the object (grasp_object=..., else the first free body).
  const objectId = query.get('grasp_object') || [...state.bodies.keys()].find((id) => !id.includes('/'));
  const holder = state.bodies.get(objectId);
  if (!holder) throw new Error(`grasp_object: no body '${objectId}' in the scene`);
  $('grasp-section').hidden = false;
  holder.add(buildGraspGhosts(set, $('grasps')));
  state.grasps = set.grasps?.length ?? 0;
}

function addContactToggle() {
  const row = document.createElement('label');
  row.innerHTML = '<input type="checkbox" id="show-contacts"> Contact points and forces <div class="sum" id="contact-legend"></div>';
  $('overlays').append(row);
  const overlay = new ContactOverlay(world, row.querySelector('#contact-legend'));
  const box = row.querySelector('input');
  box.checked = overlay.wanted = query.get('contacts') !== '0';
  overlay.visible = box.checked;
  box.onchange = () => {
    overlay.wanted = overlay.visible = box.checked;
    overlay.onChange?.();
  };
  return overlay;
}

// Body names on hover.
const raycaster = new THREE.Raycaster();
renderer.domElement.addEventListener('pointermove', (e) => {
  const rect = renderer.domElement.getBoundingClientRect();
  const pointer = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1, -((e.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const hit = raycaster.intersectObjects([...state.bodies.values()], true).find((h) => h.object.userData.bodyId);
  const label = $('hover');
  label.hidden = !hit;
  if (hit) {
    label.textContent = hit.object.userData.bodyId;
    label.style.left = `${e.clientX + 12}px`;
    label.style.top = `${e.clientY + 12}px`;
  }
});

function animate() {
  controls.update();
  renderer.render(world, camera);
  requestAnimationFrame(animate);
}

// For tests and scripts: where a body's origin appears on the canvas, in CSS pixels from its top-left corner.
function bodyScreenPosition(id) {
  const group = state.bodies.get(id);
  if (!group) return null;
  const p = group.getWorldPosition(new THREE.Vector3()).project(camera);
  const rect = renderer.domElement.getBoundingClientRect();
  return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
}
window.graspsimViewer = { state, bodyScreenPosition, background: kBackground };

async function main() {
  try {
    await loadScene();
    frameScene();
    contactOverlay = addContactToggle();
    new ResultOverlays($('overlays'), world, base, state).start();
    // Contacts ride on the pose events only while their overlay is on (?contacts=0 starts with it off).
    let poses = null;
    const connect = () => {
      poses?.close();
      poses = streamEvents(`poses${contactOverlay.wanted ? '?contacts=1' : ''}`, 'snapshot', applySnapshot);
    };
    contactOverlay.onChange = connect;
    connect();
    if (query.get('grasp_set')) await loadGrasps(query.get('grasp_set'));
    $('status').textContent = 'live';
    state.ready = true;
  } catch (error) {
    state.error = String(error.message || error);
    $('status').textContent = `error: ${state.error}`;
  }
  animate();
}
main();
