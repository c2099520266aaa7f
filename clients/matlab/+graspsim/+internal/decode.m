function out = decode(type, value)
%DECODE MATLAB values of API messages as jsondecode gives them: an N-by-1 struct array with camelCase fields,
%   numbers as double, poses 1-by-7, packed arrays as numeric arrays.
%   type is the message name: 'SceneSummary', 'Body', 'Geometry', 'Joint', 'Robot', 'TactileArray',
%   'FileInfo', 'BuiltinModel', 'BodyPose', 'JointPosition', 'SceneSnapshot', 'StepSimulationResponse',
%   'SimulationParams', 'ContactDefaults', 'SensorReading', 'WorkCycleProgress', 'GraspSet' or 'Recording'.
%   value is one decoded message (struct) or a decoded JSON array of them (struct array, cell array, or []
%   when empty: 0-by-1 result).
%   Absent fields take their protobuf defaults, so struct() gives the default message.
convert = converter(type);
list = items(value);
out = repmat(convert(struct()), 0, 1);
for k = 1:numel(list)
  out(k, 1) = convert(list{k});
end
end

function convert = converter(type)
switch type
  case 'SceneSummary', convert = @sceneSummary;
  case 'Body', convert = @body;
  case 'Geometry', convert = @geometry;
  case 'Joint', convert = @joint;
  case 'Robot', convert = @robot;
  case 'TactileArray', convert = @tactileArray;
  case 'FileInfo', convert = @fileInfo;
  case 'BuiltinModel', convert = @builtinModel;
  case 'BodyPose', convert = @bodyPose;
  case 'JointPosition', convert = @jointPosition;
  case 'SceneSnapshot', convert = @sceneSnapshot;
  case 'StepSimulationResponse', convert = @stepResult;
  case 'SimulationParams', convert = @simulationParams;
  case 'ContactDefaults', convert = @contactDefaults;
  case 'SensorReading', convert = @sensorReading;
  case 'WorkCycleProgress', convert = @workCycleProgress;
  case 'GraspSet', convert = @graspSet;
  case 'Recording', convert = @recording;
  otherwise, error('graspsim:badArgument', 'decode: unknown message type %s', type);
end
end

% --- messages ---------------------------------------------------------------------------------------------

function out = sceneSummary(msg)
% id, name, bodyCount, robotCount, revision, time (s).
out = struct('id', field(msg, 'id', ''), 'name', field(msg, 'name', ''), ...
             'bodyCount', number(field(msg, 'body_count', 0)), 'robotCount', number(field(msg, 'robot_count', 0)), ...
             'revision', number(field(msg, 'revision', 0)), 'time', number(field(msg, 'time', 0)));
end

function out = body(msg)
% id, robotId, motion ('static', 'free', 'articulated'), pose 1-by-7 (world), velocity 1-by-6 [vx vy vz wx wy wz]
% (m/s of the centre of mass and rad/s, world frame; zero for static bodies and robot links), sleeping (logical),
% mass (kg), centerOfMass 1-by-3 (m, body frame), inertia 3-by-3 (kg m^2 about the centre of mass), friction
% [static dynamic], contact (the material's contact parameters as in ContactDefaults; 0 = the scene's default),
% triangleCount, collision (Geometry array).
inertial = field(msg, 'inertial', struct());
material = field(msg, 'material', struct());
ixy = number(field(inertial, 'ixy', 0));
ixz = number(field(inertial, 'ixz', 0));
iyz = number(field(inertial, 'iyz', 0));
inertia = [number(field(inertial, 'ixx', 0)), ixy, ixz; ...
           ixy, number(field(inertial, 'iyy', 0)), iyz; ...
           ixz, iyz, number(field(inertial, 'izz', 0))];
out = struct('id', field(msg, 'id', ''), 'robotId', field(msg, 'robot_id', ''), ...
             'motion', enumName(field(msg, 'motion', ''), 'BODY_MOTION_'), ...
             'pose', pose(field(msg, 'pose', struct())), ...
             'velocity', twist(field(msg, 'velocity', struct())), ...
             'sleeping', logical(number(field(msg, 'sleeping', false))), ...
             'mass', number(field(inertial, 'mass', 0)), ...
             'centerOfMass', vec3(field(inertial, 'center_of_mass', struct()), [0 0 0]), ...
             'inertia', inertia, ...
             'friction', [number(field(material, 'static_friction', 0)), ...
                          number(field(material, 'dynamic_friction', 0))], ...
             'contact', contactDefaults(struct('stiffness', field(material, 'contact_stiffness', 0), ...
                                               'damping', field(material, 'contact_damping', 0), ...
                                               'bristle_stiffness', field(material, 'bristle_stiffness', 0), ...
                                               'bristle_damping', field(material, 'bristle_damping', 0), ...
                                               'viscous_friction', field(material, 'viscous_friction', 0), ...
                                               'stribeck_velocity', field(material, 'stribeck_velocity', 0))), ...
             'triangleCount', number(field(msg, 'triangle_count', 0)), ...
             'collision', graspsim.internal.decode('Geometry', field(msg, 'collision', [])));
end

function out = geometry(msg)
% type ('box', 'sphere', 'cylinder', 'mesh', 'meshFile' or '' when unset); size (box [x y z] full edges,
% sphere r, cylinder [r l], m; [] otherwise); vertices N-by-3 double (m, the float32 values exactly) and
% triangles M-by-3 double of 0-based indices for inline meshes; meshFile; origin 1-by-7; scale 1-by-3.
out = struct('type', '', 'size', [], 'vertices', zeros(0, 3), 'triangles', zeros(0, 3), 'meshFile', '', ...
             'origin', pose(field(msg, 'origin', struct())), 'scale', vec3(field(msg, 'scale', []), [1 1 1]));
if isfield(msg, 'box')
  out.type = 'box';
  out.size = vec3(field(msg.box, 'size', struct()), [0 0 0]);
elseif isfield(msg, 'sphere')
  out.type = 'sphere';
  out.size = number(field(msg.sphere, 'radius', 0));
elseif isfield(msg, 'cylinder')
  out.type = 'cylinder';
  out.size = [number(field(msg.cylinder, 'radius', 0)), number(field(msg.cylinder, 'length', 0))];
elseif isfield(msg, 'mesh')
  out.type = 'mesh';
  out.vertices = reshape(double(packed(field(msg.mesh, 'vertices', ''), 'single')), 3, []).';
  out.triangles = reshape(double(packed(field(msg.mesh, 'triangles', ''), 'uint32')), 3, []).';
elseif isfield(msg, 'mesh_file')
  out.type = 'meshFile';
  out.meshFile = msg.mesh_file;
end
end

function out = joint(msg)
% id, robotId, type ('revolute', 'continuous', 'prismatic', 'fixed'), parentBody, childBody, origin 1-by-7
% (parent frame), axis 1-by-3, lower, upper, velocityLimit, effortLimit, position (rad or m), velocity (rad/s
% or m/s), mimic (jointId '' when the joint follows no other, multiplier, offset).
mimic = field(msg, 'mimic', struct());
out = struct('id', field(msg, 'id', ''), 'robotId', field(msg, 'robot_id', ''), ...
             'type', enumName(field(msg, 'type', ''), 'JOINT_TYPE_'), ...
             'parentBody', field(msg, 'parent_body', ''), 'childBody', field(msg, 'child_body', ''), ...
             'origin', pose(field(msg, 'origin', struct())), 'axis', vec3(field(msg, 'axis', struct()), [0 0 0]), ...
             'lower', number(field(msg, 'lower', 0)), 'upper', number(field(msg, 'upper', 0)), ...
             'velocityLimit', number(field(msg, 'velocity_limit', 0)), ...
             'effortLimit', number(field(msg, 'effort_limit', 0)), ...
             'position', number(field(msg, 'position', 0)), ...
             'velocity', number(field(msg, 'velocity', 0)), ...
             'mimic', struct('jointId', field(mimic, 'joint_id', ''), ...
                             'multiplier', number(field(mimic, 'multiplier', 0)), ...
                             'offset', number(field(mimic, 'offset', 0))));
end

function out = robot(msg)
% id, source ('builtin:<name>' or 'urdf'), baseBody, bodyIds, jointIds, tactileArrayIds (N-by-1 cellstr).
out = struct('id', field(msg, 'id', ''), 'source', field(msg, 'source', ''), ...
             'baseBody', field(msg, 'base_body', ''), ...
             'bodyIds', {stringList(field(msg, 'body_ids', []))}, ...
             'jointIds', {stringList(field(msg, 'joint_ids', []))}, ...
             'tactileArrayIds', {stringList(field(msg, 'tactile_array_ids', []))});
end

function out = tactileArray(msg)
% id, bodyId, origin 1-by-7 (body frame; texels in its x-y plane, sensing along +z), rows (texels along y),
% cols (along x), pitch (m), thickness (m), subdivision (mesh cells per texel edge), elements ('vertices' or
% 'face_centres'), bendRadius 1-by-2 (m; a curved fingertip's radii along x and y, 0 = flat).
out = struct('id', field(msg, 'id', ''), 'bodyId', field(msg, 'body_id', ''), ...
             'origin', pose(field(msg, 'origin', struct())), ...
             'rows', number(field(msg, 'rows', 0)), 'cols', number(field(msg, 'cols', 0)), ...
             'pitch', number(field(msg, 'pitch', 0)), 'thickness', number(field(msg, 'thickness', 0)), ...
             'subdivision', number(field(msg, 'subdivision', 0)), 'elements', field(msg, 'elements', ''), ...
             'bendRadius', [number(field(msg, 'bend_radius_x', 0)), number(field(msg, 'bend_radius_y', 0))]);
end

function out = fileInfo(msg)
% path, size (bytes), sha256 (lowercase hex).
out = struct('path', field(msg, 'path', ''), 'size', number(field(msg, 'size', 0)), ...
             'sha256', field(msg, 'sha256', ''));
end

function out = builtinModel(msg)
% name, kind ('robot' or 'object'), description.
out = struct('name', field(msg, 'name', ''), 'kind', field(msg, 'kind', ''), ...
             'description', field(msg, 'description', ''));
end

function out = bodyPose(msg)
% bodyId, pose 1-by-7.
out = struct('bodyId', field(msg, 'body_id', ''), 'pose', pose(field(msg, 'pose', struct())));
end

function out = jointPosition(msg)
% jointId, position (rad or m).
out = struct('jointId', field(msg, 'joint_id', ''), 'position', number(field(msg, 'position', 0)));
end

function out = sceneSnapshot(msg)
% sequence, revision, time (s), bodyIds (N-by-1 cellstr), poses N-by-7 in the order of bodyIds, jointIds
% (J-by-1 cellstr), jointPositions J-by-1 (rad or m).
bodyIds = stringList(field(msg, 'body_ids', []));
jointIds = stringList(field(msg, 'joint_ids', []));
poses = packed(field(msg, 'body_poses', ''), 'double');
positions = packed(field(msg, 'joint_positions', ''), 'double');
if numel(poses) ~= 7 * numel(bodyIds) || numel(positions) ~= numel(jointIds)
  error('graspsim:INTERNAL', 'snapshot with %d body ids but %d pose values, %d joint ids but %d positions', ...
        numel(bodyIds), numel(poses), numel(jointIds), numel(positions));
end
out = struct('sequence', number(field(msg, 'sequence', 0)), 'revision', number(field(msg, 'revision', 0)), ...
             'time', number(field(msg, 'time', 0)), 'bodyIds', {bodyIds}, 'poses', reshape(poses, 7, []).', ...
             'jointIds', {jointIds}, 'jointPositions', positions);
end

function out = stepResult(msg)
% time (s, after the steps), steps (taken by this request), contacts (contact points in the last step),
% awakeBodies (free bodies integrated in the last step), revision.
out = struct('time', number(field(msg, 'time', 0)), 'steps', number(field(msg, 'steps', 0)), ...
             'contacts', number(field(msg, 'contacts', 0)), 'awakeBodies', number(field(msg, 'awake_bodies', 0)), ...
             'revision', number(field(msg, 'revision', 0)));
end

function out = simulationParams(msg)
% timeStep (s), substeps, integrator ('linearly_implicit_euler', 'semi_implicit_euler', 'velocity_verlet',
% 'runge_kutta_4';
% 'unspecified' = the default), gravity 1-by-3 (m/s^2), contact (ContactDefaults), sampleSpacing (m),
% sleepSpeed (m/s and rad/s), sleepTime (s).
out = struct('timeStep', number(field(msg, 'time_step', 0)), 'substeps', number(field(msg, 'substeps', 0)), ...
             'integrator', enumName(field(msg, 'integrator', ''), 'INTEGRATOR_'), ...
             'gravity', vec3(field(msg, 'gravity', []), [0 0 -9.81]), ...
             'contact', contactDefaults(field(msg, 'contact', struct())), ...
             'sampleSpacing', number(field(msg, 'sample_spacing', 0)), ...
             'sleepSpeed', number(field(msg, 'sleep_speed', 0)), 'sleepTime', number(field(msg, 'sleep_time', 0)));
end

function out = contactDefaults(msg)
% stiffness (N/m per contact point), damping (N s/m), bristleStiffness (LuGre sigma0, N/m), bristleDamping
% (sigma1, N s/m), viscousFriction (N s/m), stribeckVelocity (m/s).
out = struct('stiffness', number(field(msg, 'stiffness', 0)), 'damping', number(field(msg, 'damping', 0)), ...
             'bristleStiffness', number(field(msg, 'bristle_stiffness', 0)), ...
             'bristleDamping', number(field(msg, 'bristle_damping', 0)), ...
             'viscousFriction', number(field(msg, 'viscous_friction', 0)), ...
             'stribeckVelocity', number(field(msg, 'stribeck_velocity', 0)));
end

function out = sensorReading(msg)
% sensorId, kind ('tactile', 'gripper', 'forceTorque'; '' when unset), time (s), and the fields of its kind
% (those of the other kinds are []):
%   tactile: rows, cols, intensities rows-by-cols double (0..4095, row r along the pad's y, column c along
%     its x), forces rows-by-cols-by-3 double (N, the float32 values, pad frame: forces(r, c, :) = [x y z]),
%     intensitySum, forceSum 1-by-3 (N, pad frame).
%   gripper: fingerDistance (m), motorCurrent (A), fingerVelocity (m/s).
%   forceTorque: force 1-by-3 (N), torque 1-by-3 (N m), the joint's child frame.
out = struct('sensorId', field(msg, 'sensor_id', ''), 'kind', '', 'time', number(field(msg, 'time', 0)), ...
             'rows', [], 'cols', [], 'intensities', [], 'forces', [], 'intensitySum', [], 'forceSum', [], ...
             'fingerDistance', [], 'motorCurrent', [], 'fingerVelocity', [], 'force', [], 'torque', []);
if isfield(msg, 'tactile')
  t = msg.tactile;
  rows = number(field(t, 'rows', 0));
  cols = number(field(t, 'cols', 0));
  intensities = double(packed(field(t, 'intensities', ''), 'uint16'));
  forces = double(packed(field(t, 'forces', ''), 'single'));
  if numel(intensities) ~= rows * cols || numel(forces) ~= 3 * rows * cols
    error('graspsim:INTERNAL', 'tactile reading of %s: %d intensities and %d force values for %d x %d texels', ...
          out.sensorId, numel(intensities), numel(forces), rows, cols);
  end
  out.kind = 'tactile';
  out.rows = rows;
  out.cols = cols;
  out.intensities = reshape(intensities, cols, rows).';                   % row-major on the wire
  out.forces = permute(reshape(forces, 3, cols, rows), [3 2 1]);          % x y z per texel, row-major
  out.intensitySum = number(field(t, 'intensity_sum', 0));
  out.forceSum = vec3(field(t, 'force_sum', []), [0 0 0]);
elseif isfield(msg, 'gripper')
  g = msg.gripper;
  out.kind = 'gripper';
  out.fingerDistance = number(field(g, 'finger_distance', 0));
  out.motorCurrent = number(field(g, 'motor_current', 0));
  out.fingerVelocity = number(field(g, 'finger_velocity', 0));
elseif isfield(msg, 'force_torque')
  f = msg.force_torque;
  out.kind = 'forceTorque';
  out.force = vec3(field(f, 'force', []), [0 0 0]);
  out.torque = vec3(field(f, 'torque', []), [0 0 0]);
end
end

function out = workCycleProgress(msg)
% stage, time (s), readings (SensorReading array: both pads, then the gripper), objectPose 1-by-7 (world),
% axisPosition (m), currentLimit (A).
out = struct('stage', field(msg, 'stage', ''), 'time', number(field(msg, 'time', 0)), ...
             'readings', graspsim.internal.decode('SensorReading', field(msg, 'readings', [])), ...
             'objectPose', pose(field(msg, 'object_pose', struct())), ...
             'axisPosition', number(field(msg, 'axis_position', 0)), ...
             'currentLimit', number(field(msg, 'current_limit', 0)));
end

function out = graspSet(msg)
% A grasp set (GraspService.PlanGrasps / GetGraspSet), one row per grasp, best epsilon first, object frame:
% epsilon, volume N-by-1, forceClosure N-by-1 logical, preshape N-by-1 cellstr, approach, target N-by-3,
% handPose N-by-7, jointPositions N-by-J (J = numel(jointIds)), contacts N-by-1 cell of structs (point, normal
% K-by-3, link K-by-1 cellstr); setId, hand, fromStore, candidates, collisions, simulated, forceClosureCount,
% seconds (s, simulate + score).
grasps = items(field(msg, 'grasps', []));
jointIds = stringList(field(msg, 'joint_ids', []));
n = numel(grasps);
out = struct('setId', field(msg, 'set_id', ''), 'hand', field(msg, 'hand', ''), ...
             'fromStore', logical(field(msg, 'from_store', false)), ...
             'candidates', number(field(msg, 'candidates', 0)), 'collisions', number(field(msg, 'collisions', 0)), ...
             'simulated', number(field(msg, 'simulated', 0)), ...
             'forceClosureCount', number(field(msg, 'force_closure', 0)), 'seconds', number(field(msg, 'seconds', 0)), ...
             'jointIds', {jointIds}, 'epsilon', zeros(n, 1), 'volume', zeros(n, 1), 'forceClosure', false(n, 1), ...
             'preshape', {cell(n, 1)}, 'approach', zeros(n, 3), 'target', zeros(n, 3), 'handPose', zeros(n, 7), ...
             'jointPositions', zeros(n, numel(jointIds)), 'contacts', {cell(n, 1)});
for k = 1:n
  g = grasps{k};
  c = field(g, 'candidate', struct());
  out.epsilon(k) = number(field(g, 'epsilon', 0));
  out.volume(k) = number(field(g, 'volume', 0));
  out.forceClosure(k) = logical(field(g, 'force_closure', false));
  out.preshape{k} = field(c, 'preshape', '');
  out.approach(k, :) = vec3(field(c, 'approach', []), [0 0 0]);
  out.target(k, :) = vec3(field(c, 'target', []), [0 0 0]);
  out.handPose(k, :) = pose(field(g, 'hand_pose', struct()));
  q = field(g, 'joint_positions', []);
  out.jointPositions(k, 1:numel(q)) = cellfun(@number, num2cell(q(:).'));
  list = items(field(g, 'contacts', []));
  contacts = struct('point', zeros(numel(list), 3), 'normal', zeros(numel(list), 3), 'link', {cell(numel(list), 1)});
  for j = 1:numel(list)
    contacts.point(j, :) = vec3(field(list{j}, 'point', []), [0 0 0]);
    contacts.normal(j, :) = vec3(field(list{j}, 'normal', []), [0 0 0]);
    contacts.link{j} = field(list{j}, 'link', '');
  end
  out.contacts{k} = contacts;
end
end

% --- pieces -----------------------------------------------------------------------------------------------

function out = recording(msg)
% name (the file name, the recording's id), sceneId, path (on the server), ros2Path ('' without the ros2 group),
% active (logical), frames, messages, droppedFrames, bytes, startTime, endTime (s, simulation time).
out = struct('name', field(msg, 'name', ''), 'sceneId', field(msg, 'scene_id', ''), 'path', field(msg, 'path', ''), ...
             'ros2Path', field(msg, 'ros2_path', ''), 'active', logical(number(field(msg, 'active', false))), ...
             'frames', number(field(msg, 'frames', 0)), 'messages', number(field(msg, 'messages', 0)), ...
             'droppedFrames', number(field(msg, 'dropped_frames', 0)), 'bytes', number(field(msg, 'bytes', 0)), ...
             'startTime', number(field(msg, 'start_time', 0)), 'endTime', number(field(msg, 'end_time', 0)));
end

function value = field(msg, name, default)
% msg.(name), or default when absent (protobuf's JSON omits unset messages and oneof members).
if isstruct(msg) && isfield(msg, name)
  value = msg.(name);
else
  value = default;
end
end

function value = number(x)
% A double from a JSON number or from the strings protobuf uses for 64-bit integers and NaN/Infinity.
if ischar(x)
  value = str2double(x);
elseif isempty(x)
  value = 0;
else
  value = double(x);
end
end

function list = items(x)
% A decoded JSON array of objects as an N-by-1 cell of structs: jsondecode gives a struct array when the
% objects have the same fields, a cell array when they differ (different oneof members), [] when empty.
if isempty(x)
  list = cell(0, 1);
elseif iscell(x)
  list = x(:);
else
  list = num2cell(x(:));
end
end

function list = stringList(x)
% A decoded JSON array of strings (a char row when it has one element after all, [] when empty) as an
% N-by-1 cellstr.
if isempty(x)
  list = cell(0, 1);
elseif ischar(x)
  list = {x};
else
  list = x(:);
end
end

function name = enumName(value, prefix)
% A protobuf enum name without its prefix, in lower case: ('BODY_MOTION_FREE', 'BODY_MOTION_') -> 'free'.
if isempty(value)
  value = 'UNSPECIFIED';
elseif ~ischar(value)
  value = sprintf('%d', value);
end
if strncmp(value, prefix, numel(prefix))
  value = value(numel(prefix) + 1:end);
end
name = lower(value);
end

function values = pose(msg)
% 1-by-7 [x y z qw qx qy qz]; an absent position is the origin, an absent orientation the identity.
values = [vec3(field(msg, 'position', struct()), [0 0 0]), [1 0 0 0]];
if isfield(msg, 'orientation')
  q = msg.orientation;
  values(4:7) = [number(field(q, 'w', 0)), number(field(q, 'x', 0)), number(field(q, 'y', 0)), ...
                 number(field(q, 'z', 0))];
end
end

function values = twist(msg)
% 1-by-6 [vx vy vz wx wy wz] from a Twist (linear m/s, angular rad/s); absent parts are zero.
values = [vec3(field(msg, 'linear', []), [0 0 0]), vec3(field(msg, 'angular', []), [0 0 0])];
end

function values = vec3(msg, default)
% 1-by-3 [x y z]; default when the message is absent.
if ~isstruct(msg)
  values = default;
  return;
end
values = [number(field(msg, 'x', 0)), number(field(msg, 'y', 0)), number(field(msg, 'z', 0))];
end

function values = packed(text, type)
% A column of class type ('double', 'single', 'uint32', 'uint16') from base64 of packed little-endian numbers.
if isempty(text)
  values = zeros(0, 1, type);
  return;
end
bytes = reshape(uint8(matlab.net.base64decode(text)), 1, []);
width = numel(typecast(zeros(1, 1, type), 'uint8'));
if mod(numel(bytes), width) ~= 0
  error('graspsim:INTERNAL', 'a packed %s array of %d bytes is not a multiple of %d', type, numel(bytes), width);
end
values = reshape(typecast(bytes, type), [], 1);
[~, ~, endian] = computer();
if endian == 'B'
  values = swapbytes(values);
end
end
