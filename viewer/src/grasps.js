// Planned grasps as hand ghosts on their object: GET /view/<scene>/grasps?set_id=... (GraspService.GetGraspSet),
// best ε first. A ghost is schematic — the hand's palm frame where the fingers closed (hand_pose, object
// frame: the hand's +z is the approach), an approach arrow and the contacts with their normals — since the
// grasp set carries the hand's name and joint positions but not its link meshes.
import * as THREE from 'three';
import { applyPose } from './geometry.js';

const kShown = 10;

export function buildGraspGhosts(set, list) {
  const root = new THREE.Group();
  root.name = 'grasp ghosts';
  const grasps = (set.grasps || []).slice(0, kShown);
  grasps.forEach((grasp, rank) => {
    const opacity = 0.75 - 0.6 * (rank / Math.max(1, grasps.length - 1));
    const color = new THREE.Color().setHSL(0.33 * (1 - rank / Math.max(1, grasps.length)), 0.8, 0.5);
    const ghost = new THREE.Group();
    const hand = new THREE.Group();
    applyPose(hand, grasp.hand_pose);
    const material = new THREE.MeshBasicMaterial({ color, transparent: true, opacity, depthWrite: false });
    const palm = new THREE.Mesh(new THREE.BoxGeometry(0.06, 0.02, 0.01), material);
    palm.position.z = -0.005;
    hand.add(palm, new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(0, 0, -0.06), 0.06, color, 0.012, 0.008));
    ghost.add(hand);
    for (const contact of grasp.contacts || []) {
      const point = new THREE.Vector3(contact.point?.x ?? 0, contact.point?.y ?? 0, contact.point?.z ?? 0);
      const normal = new THREE.Vector3(contact.normal?.x ?? 0, contact.normal?.y ?? 0, contact.normal?.z ?? 0).normalize();
      const dot = new THREE.Mesh(new THREE.SphereGeometry(0.003), material);
      dot.position.copy(point);
      ghost.add(dot, new THREE.ArrowHelper(normal, point.clone().addScaledVector(normal, -0.02), 0.02, color, 0.006, 0.004));
    }
    root.add(ghost);
    const item = document.createElement('li');
    item.textContent = `ε = ${grasp.epsilon.toFixed(4)} · ${grasp.candidate?.preshape || set.preshapes?.[0] || ''} · ${grasp.contacts?.length ?? 0} contacts`;
    item.onmouseenter = () => root.children.forEach((g) => { g.visible = g === ghost; });
    item.onmouseleave = () => root.children.forEach((g) => { g.visible = true; });
    list.append(item);
  });
  return root;
}
