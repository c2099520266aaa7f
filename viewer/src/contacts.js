// Contact points and force vectors of the last simulation step, from the pose events (contacts=1, packed
// float32): 6 numbers per contact, point (m) and force on the first body (N), world frame. Arrows are scaled per snapshot so that
// the largest force is kArrow long; the legend says how many newtons that is.
import * as THREE from 'three';

const kArrow = 0.03;  // m

export class ContactOverlay {
  constructor(world, legend) {
    this.legend = legend;
    this.points = new THREE.Points(new THREE.BufferGeometry(),
                                   new THREE.PointsMaterial({ color: 0x3de0ff, size: 4, sizeAttenuation: false, depthTest: false }));
    this.arrows = new THREE.LineSegments(new THREE.BufferGeometry(),
                                         new THREE.LineBasicMaterial({ color: 0xffe14d, depthTest: false }));
    this.points.renderOrder = this.arrows.renderOrder = 1;  // drawn over the bodies they touch
    world.add(this.points, this.arrows);
    this.count = 0;
  }

  set visible(on) { this.points.visible = this.arrows.visible = on; }

  update(contacts) {
    const n = Math.floor((contacts?.length ?? 0) / 6);
    const points = new Float32Array(3 * n), segments = new Float32Array(6 * n);
    let largest = 0;
    for (let i = 0; i < n; ++i) largest = Math.max(largest, Math.hypot(contacts[6 * i + 3], contacts[6 * i + 4], contacts[6 * i + 5]));
    const scale = largest > 0 ? kArrow / largest : 0;
    for (let i = 0; i < n; ++i) {
      for (let k = 0; k < 3; ++k) {
        const p = contacts[6 * i + k];
        points[3 * i + k] = p;
        segments[6 * i + k] = p;
        segments[6 * i + 3 + k] = p + scale * contacts[6 * i + 3 + k];
      }
    }
    this.points.geometry.setAttribute('position', new THREE.BufferAttribute(points, 3));
    this.arrows.geometry.setAttribute('position', new THREE.BufferAttribute(segments, 3));
    this.points.geometry.computeBoundingSphere();
    this.arrows.geometry.computeBoundingSphere();
    this.count = n;
    this.legend.textContent = n ? `${n} contact points; largest force ${largest.toPrecision(3)} N = ${kArrow * 100} cm arrow`
                                : 'no contacts in the last step';
  }
}
