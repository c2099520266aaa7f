function graspsim_demo(url, keep)
%GRASPSIM_DEMO graspsim demo: a Schunk PG70 gripper above a 5 cm cube on a table (MATLAB or GNU Octave).
%
%   graspsim_demo                      % server's HTTP gateway at http://127.0.0.1:8080
%   graspsim_demo('http://127.0.0.1:8080')
%   graspsim_demo('http://127.0.0.1:8080', true) % keep the scene on the server (default: delete it)
%
%   Stages: list the built-in models, build the scene, open the gripper, print what the server holds
%   (bodies, joints, tactile arrays, one live snapshot), then simulate: drop a second cube onto the table,
%   step 1.5 s and print where it came to rest. Last the tactile sensors, in a second scene: a PG70 on a
%   vertical axis closes on a cube and reads its pads, then runs one grasp work cycle. Needs clients/matlab on the path:
%   addpath('<repo>/clients/matlab'). A refused request raises graspsim:<STATUS> with the server's message.
if nargin < 1 || isempty(url)
  url = 'http://127.0.0.1:8080';
end
if nargin < 2
  keep = false;
end
tableTopZ = 0.75;       % m, top surface of the built-in table placed at the origin
cubeEdge = 0.05;        % m
gripperHeight = 0.25;   % m above the table top
fingerOpening = 0.03;   % m, finger_left_joint (finger_right_joint mimics it)
pointingDown = [0 1 0 0];  % quaternion (w x y z): half a turn about x, gripper z (approach) = world -z
dropHeight = 0.10;      % m between the table top and the bottom of the dropped cube
settleTime = 1.5;       % s of simulation

c = graspsim.Client(url);
fprintf('connected to graspsim at %s\n', url);
listModels(c);

scene = c.createScene('demo');
c.addObject(scene.id, 'table', 'Builtin', 'table');
c.addObject(scene.id, 'cube_5cm', 'Builtin', 'cube_5cm', 'Pose', [0 0 tableTopZ + cubeEdge / 2, 1 0 0 0]);
c.addRobot(scene.id, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 tableTopZ + gripperHeight, pointingDown]);
fprintf('\nscene ''%s'' created: id %s\n', scene.name, scene.id);

revision = c.setJointPositions(scene.id, {'pg70/finger_left_joint'}, fingerOpening);
fprintf('gripper opened to %.0f mm per finger (revision %d)\n', fingerOpening * 1000, revision);

state = c.getScene(scene.id);
printBodies(state.bodies);
printJoints(state.joints);
printTactileArrays(state.tactileArrays);
printSnapshot(c.watchScene(scene.id, 1));

% Simulation: a second 5 cm cube (100 g) falls onto the table beside the gripper and comes to rest.
c.addObject(scene.id, 'dropped_cube', 'Box', cubeEdge * [1 1 1], 'Mass', 0.1, ...
            'Pose', [0.3 0.2 tableTopZ + dropHeight + cubeEdge / 2, 1 0 0 0]);
params = c.getSimulationParams(scene.id);
fprintf('\nsimulation: time step %.1f ms, %s, gravity [%g %g %g] m/s^2\n', params.timeStep * 1000, ...
        params.integrator, params.gravity);
fprintf('  dropped_cube released %.0f mm above the table\n', dropHeight * 1000);
result = c.stepSimulation(scene.id, 'Duration', settleTime);
cube = sceneBody(c.getScene(scene.id), 'dropped_cube');
fprintf('  after %.3f s (%d steps): %d contact points, %d awake bodies\n', result.time, result.steps, ...
        result.contacts, result.awakeBodies);
states = {'awake', 'asleep'};
fprintf('  dropped_cube rests at z = %.4f m (table top + %.1f mm), speed %.1e m/s, %s\n', cube.pose(3), ...
        (cube.pose(3) - tableTopZ) * 1000, norm(cube.velocity(1:3)), states{cube.sleeping + 1});
if ~keep
  c.deleteScene(scene.id);
end
tactileDemo(c, tableTopZ, cubeEdge, keep);
end

function tactileDemo(c, tableTopZ, cubeEdge, keep)
% A PG70 carried by a vertical axis (built-in 'schunk_pg70_on_z_axis', its base 0.3 m above the table, the
% fingertips 9 cm above the cube at z_axis = 0) is lowered around the cube and closed on it; then its pads and
% its gripper sensor are read. Last the same cell runs the grasp work cycle in a fresh scene.
cellBaseZ = tableTopZ + 0.30;   % m
cubePose = [0 0 tableTopZ + cubeEdge / 2, 1 0 0 0];
scene = buildCell(c, 'tactile demo', cubePose, cellBaseZ);
c.setJointPositions(scene.id, {'cell/z_axis', 'cell/finger_left_joint'}, [-0.14, 0.03]);  % lowered, open
c.setActuator(scene.id, 'cell/z_axis', 'position', -0.14);                 % held there (it would slide down)
c.setActuator(scene.id, 'cell/finger_left_joint', 'velocity', -0.02, 1.0);  % close at 2 cm/s, at most 1 A
c.stepSimulation(scene.id, 'Duration', 1.5);
fprintf('\ntactile: the PG70 closed on the cube for 1.5 s\n');
for pad = {'cell/pad_left', 'cell/pad_right'}
  r = c.sampleSensor(scene.id, pad{1});
  fprintf('  %-14s %d x %d texels, %d touched, intensity sum %d, force [%.2f %.2f %.2f] N\n', r.sensorId, ...
          r.rows, r.cols, nnz(r.intensities), r.intensitySum, r.forceSum);
end
g = c.sampleSensor(scene.id, 'cell/gripper');
fprintf('  %-14s fingers %.1f mm apart, motor current %.2f A\n', g.sensorId, g.fingerDistance * 1000, ...
        g.motorCurrent);
png = c.tactileImage(scene.id, 'cell/pad_left', 20);  % fwrite(fopen('pad.png', 'w'), png) saves it
fprintf('  heat map of cell/pad_left: a %d-byte PNG\n', numel(png));
if ~keep
  c.deleteScene(scene.id);
end

% The work cycle: approach, grasp (force control of the tactile sum at the set-point), lift 5 cm, hold 0.5 s,
% move down, release.
scene = buildCell(c, 'tactile work cycle', cubePose, cellBaseZ);
cycle = c.runWorkCycle(scene.id, 'cell', 'cube', 'TactileSetpoint', 30000, 'HoldTime', 0.5);
carried = find(strcmp(cycle.stage, 'lift') | strcmp(cycle.stage, 'hold'));
fprintf('\nwork cycle: %d frames over %.2f s, stages %s\n', numel(cycle.time), cycle.time(end), ...
        strjoin(unique(cycle.stage, 'stable').', ' > '));
fprintf('  peak sums %d (left) / %d (right), set-point %d\n', max(cycle.leftSum), max(cycle.rightSum), ...
        cycle.tactileSetpoint);
fprintf('  cube lifted %.1f mm, put back within %.1f mm of where it was\n', ...
        1000 * (cycle.objectPosition(carried(end), 3) - cycle.objectPosition(carried(1), 3)), ...
        1000 * abs(cycle.objectPosition(end, 3) - cycle.objectPosition(1, 3)));
if ~keep
  c.deleteScene(scene.id);
end
end

function scene = buildCell(c, name, cubePose, cellBaseZ)
% A scene with the table, the cube resting on it and the gripper cell 'cell' above the cube.
scene = c.createScene(name);
c.addObject(scene.id, 'table', 'Builtin', 'table');
c.addObject(scene.id, 'cube', 'Builtin', 'cube_5cm', 'Pose', cubePose);
c.addRobot(scene.id, 'cell', 'Builtin', 'schunk_pg70_on_z_axis', 'BasePose', [0 0 cellBaseZ, 1 0 0 0]);
end

function b = sceneBody(scene, id)
b = scene.bodies(strcmp({scene.bodies.id}, id));
end

function listModels(c)
fprintf('built-in models:\n');
models = c.builtinModels();
for k = 1:numel(models)
  fprintf('  %-6s %-12s %s\n', models(k).kind, models(k).name, models(k).description);
end
end

function text = formatPose(pose)
text = sprintf('p=(%+.4f, %+.4f, %+.4f) m  q=(%+.3f, %+.3f, %+.3f, %+.3f)', pose);
end

function printBodies(bodies)
fprintf('\nbodies (%d):\n', numel(bodies));
for k = 1:numel(bodies)
  b = bodies(k);
  fprintf('  %-18s %-11s %7.3f kg  %s\n', b.id, b.motion, b.mass, formatPose(b.pose));
end
end

function printJoints(joints)
fprintf('\njoints (%d):\n', numel(joints));
for k = 1:numel(joints)
  j = joints(k);
  unit = 'rad';
  if strcmp(j.type, 'prismatic')
    unit = 'm';
  end
  follows = '';
  if ~isempty(j.mimic.jointId)
    follows = ['  mimics ' j.mimic.jointId];
  end
  fprintf('  %-24s %-9s %.4f %s  limits [%.4f, %.4f]%s\n', j.id, j.type, j.position, unit, j.lower, j.upper, follows);
end
end

function printTactileArrays(pads)
fprintf('\ntactile arrays (%d):\n', numel(pads));
for k = 1:numel(pads)
  p = pads(k);
  fprintf('  %-16s on %-18s %d rows x %d cols, pitch %.1f mm\n', p.id, p.bodyId, p.rows, p.cols, p.pitch * 1000);
end
end

function printSnapshot(snap)
fprintf('\nsnapshot %d (revision %d, t = %.3f s): %d bodies, %d joints\n', snap.sequence, snap.revision, ...
        snap.time, numel(snap.bodyIds), numel(snap.jointIds));
for k = 1:numel(snap.bodyIds)
  fprintf('  %-18s z = %.4f m\n', snap.bodyIds{k}, snap.poses(k, 3));
end
for k = 1:numel(snap.jointIds)
  fprintf('  %-24s %.4f\n', snap.jointIds{k}, snap.jointPositions(k));
end
end
