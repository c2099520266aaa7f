// Results drawn over the scene: the symmetry plane of the last shape completion added to it (with the body it
// added) and the tip path of the last arm path planned in it (GET overlays.json, rpc/scene_overlays.h). Polled
// once a second and redrawn only when the server's version changes; each has its own checkbox.
import * as THREE from 'three';

const kPollMs = 1000;

function toggleRow(container, label) {
  const row = document.createElement('label');
  row.hidden = true;
  row.innerHTML = `<input type="checkbox" checked> ${label} <div class="sum"></div>`;
  container.append(row);
  return { row, box: row.querySelector('input'), note: row.querySelector('.sum') };
}

function planeMesh(completion) {
  const size = Math.max(0.05, 1.2 * completion.size);
  const material = new THREE.MeshBasicMaterial({ color: 0x35c2e0, transparent: true, opacity: 0.3, side: THREE.DoubleSide, depthWrite: false });
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(size, size), material);
  const edge = new THREE.LineSegments(new THREE.EdgesGeometry(plane.geometry), new THREE.LineBasicMaterial({ color: 0x35c2e0 }));
  plane.add(edge);
  plane.position.set(...completion.point);
  plane.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), new THREE.Vector3(...completion.normal).normalize());
  return plane;
}

function pathLine(path) {
  const group = new THREE.Group();
  const points = path.tip_points.map((p) => new THREE.Vector3(...p));
  group.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(points), new THREE.LineBasicMaterial({ color: 0xffb000 })));
  [[points[0], 0x60d060], [points[points.length - 1], 0xe05050]].forEach(([point, color]) => {
    const dot = new THREE.Mesh(new THREE.SphereGeometry(0.008), new THREE.MeshBasicMaterial({ color }));
    dot.position.copy(point);
    group.add(dot);
  });
  return group;
}

export class ResultOverlays {
  constructor(container, world, base, state) {
    this.world = world;
    this.base = base;
    this.state = state;
    this.version = -1;
    this.completion = toggleRow(container, 'Symmetry plane of the completed shape');
    this.path = toggleRow(container, 'Arm path (tip)');
    this.objects = { completion: null, path: null };
    for (const [key, toggle] of [['completion', this.completion], ['path', this.path]]) {
      toggle.box.onchange = () => { if (this.objects[key]) this.objects[key].visible = toggle.box.checked; };
    }
    state.overlays = { version: 0, completion: null, armPathPoints: 0 };
  }

  start() {
    const poll = () => this.load().catch(() => {}).finally(() => setTimeout(poll, kPollMs));
    poll();
  }

  replace(key, object, toggle) {
    if (this.objects[key]) this.world.remove(this.objects[key]);
    this.objects[key] = object;
    if (object) {
      object.visible = toggle.box.checked;
      this.world.add(object);
    }
    toggle.row.hidden = !object;
  }

  async load() {
    const response = await fetch(`${this.base}/overlays.json`);
    if (!response.ok) return;
    const overlays = await response.json();
    if (overlays.version === this.version) return;
    this.version = overlays.version;
    const { completion, arm_path: path } = overlays;
    this.replace('completion', completion ? planeMesh(completion) : null, this.completion);
    if (completion) this.completion.note.textContent = `${completion.body_id} · score ${completion.score.toFixed(1)}`;
    this.replace('path', path && path.tip_points.length ? pathLine(path) : null, this.path);
    if (path) this.path.note.textContent = `${path.arm_id} · ${path.duration.toFixed(2)} s${path.direct ? ' · straight' : ''}`;
    this.state.overlays = { version: overlays.version, completion: completion?.body_id ?? null, armPathPoints: path?.tip_points.length ?? 0 };
  }
}
