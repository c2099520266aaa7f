// Three.js objects from the scene's JSON (GET /view/<scene>/scene.json: SceneService.GetScene with inline
// geometry, protobuf JSON mapping: snake_case fields, bytes as base64). World frame z up, metres.
import * as THREE from 'three';

export function decodeBase64(text) {
  const binary = atob(text || '');
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes.buffer;
}

const vec = (v, fallback = 0) => new THREE.Vector3(v?.x ?? fallback, v?.y ?? fallback, v?.z ?? fallback);

// A proto Pose onto an Object3D (absent orientation = identity).
export function applyPose(object, pose) {
  object.position.copy(vec(pose?.position));
  const q = pose?.orientation;
  if (q && (q.w || q.x || q.y || q.z)) object.quaternion.set(q.x, q.y, q.z, q.w);
  else object.quaternion.identity();
}

function shapeGeometry(shape) {
  if (shape.box) {
    const s = vec(shape.box.size);
    return new THREE.BoxGeometry(s.x, s.y, s.z);
  }
  if (shape.sphere) return new THREE.SphereGeometry(shape.sphere.radius, 32, 16);
  if (shape.cylinder) {
    // graspsim's cylinders lie along z, three's along y.
    const geometry = new THREE.CylinderGeometry(shape.cylinder.radius, shape.cylinder.radius, shape.cylinder.length, 32);
    geometry.rotateX(Math.PI / 2);
    return geometry;
  }
  if (shape.mesh) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(decodeBase64(shape.mesh.vertices)), 3));
    geometry.setIndex(new THREE.BufferAttribute(new Uint32Array(decodeBase64(shape.mesh.triangles)), 1));
    geometry.computeVertexNormals();
    return geometry;
  }
  return null;  // a mesh_file the server did not inline: nothing to draw
}

function bodyColor(body) {
  if (body.motion === 'BODY_MOTION_STATIC') return 0x8a8f96;
  if (body.motion === 'BODY_MOTION_ARTICULATED') return 0x5d7fa8;
  return 0xe0913a;
}

// One group per body (named by its id, posed by the snapshots) holding its collision shapes.
export function buildBodies(scene) {
  const groups = new Map();
  for (const body of scene.bodies || []) {
    const group = new THREE.Group();
    group.name = body.id;
    group.userData.bodyId = body.id;
    group.userData.isStatic = body.motion === 'BODY_MOTION_STATIC';
    const material = new THREE.MeshStandardMaterial({ color: bodyColor(body), roughness: 0.6, metalness: 0.1 });
    for (const shape of body.collision || []) {
      const geometry = shapeGeometry(shape);
      if (!geometry) continue;
      const mesh = new THREE.Mesh(geometry, material);
      applyPose(mesh, shape.origin);
      if (shape.mesh && shape.scale) mesh.scale.copy(vec(shape.scale, 1));
      mesh.userData.bodyId = body.id;
      group.add(mesh);
    }
    applyPose(group, body.pose);
    groups.set(body.id, group);
  }
  return groups;
}

// A tactile pad as a thin plane on its body (texels in the pad's x-y plane, sensing along +z), textured by
// its heat map canvas.
export function buildPad(array, canvas) {
  const width = array.cols * array.pitch, height = array.rows * array.pitch;
  const texture = new THREE.CanvasTexture(canvas);
  texture.magFilter = THREE.NearestFilter;
  const plane = new THREE.Mesh(new THREE.PlaneGeometry(width, height),
                               new THREE.MeshBasicMaterial({ map: texture, side: THREE.DoubleSide, transparent: true, opacity: 0.9 }));
  const holder = new THREE.Group();
  applyPose(holder, array.origin);
  plane.position.z = 1e-4;  // just above the pad surface, so it does not flicker against the finger
  holder.add(plane);
  holder.userData.texture = texture;
  return holder;
}
