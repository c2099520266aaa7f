// Overlays whose data the server does not serve yet. Each is a named slot with its source stated, so that the
// capability that produces the data fills in `load` and nothing here pretends: no made-up geometry is drawn.
//   completion  symmetry plane and completed mesh of a shape completion (perception, issue 5)
//   arm path    the arm path of a plan (motion planning, issue 7: PlanArmPath waypoints)
export const overlayHooks = [
  { id: 'completion', label: 'Symmetry plane and completed mesh', source: 'shape completion (issue 5), not served yet', load: null },
  { id: 'arm-path', label: 'Arm path of a plan', source: 'motion planning (issue 7), not served yet', load: null },
];

export function addOverlayHooks(container, world) {
  for (const hook of overlayHooks) {
    const row = document.createElement('div');
    row.dataset.hook = hook.id;
    if (hook.load) {
      row.textContent = hook.label;
      hook.load(world);
    } else {
      row.className = 'hook';
      row.textContent = `${hook.label}: ${hook.source}`;
    }
    container.append(row);
  }
}
