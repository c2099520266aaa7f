function failed = test_client(url)
%TEST_CLIENT End-to-end tests of the Matlab/Octave client (clients/matlab) against a running graspsim server.
%
%   failed = test_client('http://127.0.0.1:8080')   % or the URL in the environment variable GRASPSIM_HTTP_URL
%
%   Each test is a local function test_*(c, sceneId) given a client and a fresh empty scene (deleted after).
%   Prints one line per test and a summary "N passed, M failed"; returns M. tests/matlab/run.sh starts the
%   server and runs this in GNU Octave. Uses clients/matlab and clients/matlab/examples (added to the path).
if nargin < 1 || isempty(url)
  url = getenv('GRASPSIM_HTTP_URL');
end
if isempty(url)
  error('test_client: give the gateway URL or set GRASPSIM_HTTP_URL');
end
here = fileparts(mfilename('fullpath'));
addpath(fullfile(here, '..', '..', 'clients', 'matlab'));
addpath(fullfile(here, '..', '..', 'clients', 'matlab', 'examples'));

tests = {@test_list_methods, @test_scene_lifecycle, @test_builtin_models, @test_text_round_trip, ...
         @test_primitive_objects_and_inertia, @test_builtin_objects, @test_inline_mesh_round_trip, ...
         @test_mesh_inertia_from_mass, @test_large_request_body, @test_upload_file_chunks, @test_upload_large_file_and_mesh_file, ...
         @test_urdf_robot_with_files, @test_urdf_robot_by_path, @test_pg70_structure_and_tactile_arrays, @test_mimic_joint_follows, ...
         @test_pose_round_trip, @test_joint_positions, @test_watch_scene, @test_remove_body, @test_generic_call, ...
         @test_error_nan_pose, @test_error_bad_quaternion, @test_error_unknown_scene, @test_error_duplicate_name, ...
         @test_error_joint_outside_limits, @test_body_and_joint_velocity_fields, @test_simulation_cube_settles, ...
         @test_simulation_step_forms, @test_simulation_params_round_trip, @test_error_simulation_params, ...
         @test_actuator_moves_fingers, @test_error_actuator, ...
         @test_tactile_sample_untouched, @test_tactile_image_png, @test_gripper_reading, ...
         @test_tactile_grasp_reading, @test_stream_sensors, @test_work_cycle_lifts_cube, @test_error_tactile, ...
         @test_plan_grasps, @test_recording_falling_box, @test_error_recording, ...
         @test_error_other_services_unimplemented, @test_error_client_side_arguments, @test_error_unreachable_server, ...
         @test_demo_runs};
c = graspsim.Client(url, 'Timeout', 30);
passed = 0;
failed = 0;
for k = 1:numel(tests)
  name = func2str(tests{k});
  sceneId = '';
  try
    scene = c.createScene(name);
    sceneId = scene.id;
    tests{k}(c, sceneId);
    passed = passed + 1;
    fprintf('  ok    %s\n', name);
  catch err
    failed = failed + 1;
    fprintf('  FAIL  %s: [%s] %s\n', name, err.identifier, err.message);
    if ~isempty(err.stack)
      fprintf('        at %s line %d\n', err.stack(1).name, err.stack(1).line);
    end
  end
  if ~isempty(sceneId)
    try
      c.deleteScene(sceneId);
    catch err  %#ok<NASGU> a test may delete its own scene
    end
  end
end
fprintf('%d passed, %d failed\n', passed, failed);
end

% --- tests ------------------------------------------------------------------------------------------------

function test_list_methods(c, ~)
listing = c.listMethods();
services = listing.services;
names = {services.name};
check(any(strcmp(names, 'graspsim.v1.SceneService')), 'SceneService not listed: %s', strjoin(names, ', '));
scene = services(strcmp(names, 'graspsim.v1.SceneService'));
methodList = methodNames(scene.methods);
for m = {'CreateScene', 'GetScene', 'UploadFile', 'WatchScene', 'StepSimulation', 'SetSimulationParams', ...
         'GetSimulationParams', 'SetActuators'}
  check(any(strcmp(methodList, m{1})), '%s not listed', m{1});
end
end

function test_scene_lifecycle(c, ~)
a = c.createScene('lifecycle a');
b = c.createScene('lifecycle b');
check(ischar(a.id) && ~isempty(a.id) && ~strcmp(a.id, b.id), 'scene ids %s, %s', a.id, b.id);
check(strcmp(a.name, 'lifecycle a') && a.bodyCount == 0 && a.robotCount == 0 && a.time == 0, 'summary of a new scene');
check(isa(a.revision, 'double'), 'revision is %s, not double', class(a.revision));
listed = c.listScenes();
check(size(listed, 2) == 1 && listed(1).revision >= 0, 'listScenes gives an N-by-1 struct array');
check(any(strcmp({listed.id}, a.id)) && any(strcmp({listed.id}, b.id)), 'listScenes misses the new scenes');
scene = c.getScene(a.id);
check(strcmp(scene.summary.id, a.id) && strcmp(scene.summary.name, 'lifecycle a'), 'getScene summary');
check(isempty(scene.bodies) && isempty(scene.joints) && isempty(scene.robots) && isempty(scene.tactileArrays) ...
      && isempty(scene.files), 'a new scene is empty');
check(isfield(scene.bodies, 'pose') && isfield(scene.joints, 'mimic'), 'empty arrays keep their fields');
c.deleteScene(a.id);
c.deleteScene(b.id);
expectError(@() c.getScene(a.id), 'graspsim:NOT_FOUND', {a.id});
after = c.listScenes();
check(~any(strcmp({after.id}, a.id)), 'deleted scene still listed');
end

function test_plan_grasps(c, sid)
c.addObject(sid, 'table', 'Builtin', 'table');
c.addObject(sid, 'cube', 'Builtin', 'cube_5cm', 'Pose', [0 0 0.775 1 0 0 0]);
r = c.planGrasps('schunk_pg70', 'SceneId', sid, 'BodyId', 'cube', 'Spacing', 0.02, 'MaxGrasps', 5, 'Timeout', 120);
check(~r.fromStore && r.candidates > 0 && r.collisions > 0, 'planned: %d candidates, %d collisions', ...
      r.candidates, r.collisions);
check(numel(r.epsilon) >= 1 && numel(r.epsilon) <= 5 && all(r.epsilon > 0) && all(diff(r.epsilon) <= 0), ...
      'epsilon best first');
check(isequal(size(r.handPose), [numel(r.epsilon), 7]) && size(r.jointPositions, 2) == numel(r.jointIds), ...
      'pose and joint arrays');
check(all(ismember(r.contacts{1}.link, {'base_link', 'finger_left', 'finger_right'})), 'contact links');
again = c.planGrasps('schunk_pg70', 'SceneId', sid, 'BodyId', 'cube', 'Spacing', 0.02, 'MaxGrasps', 5);
check(again.fromStore && strcmp(again.setId, r.setId), 'second request from the store');
expectError(@() c.planGrasps('ur5', 'SceneId', sid, 'BodyId', 'cube'), 'graspsim:INVALID_ARGUMENT', {'hand', 'ur5'});
expectError(@() c.planGrasps('schunk_pg70', 'SceneId', sid, 'BodyId', 'cube', 'Friction', 0), ...
            'graspsim:INVALID_ARGUMENT', {'friction'});
end

function test_builtin_models(c, ~)
models = c.builtinModels();
names = {models.name};
kinds = {models.kind};
check(all(ismember({'table', 'cube_5cm', 'schunk_pg70'}, names)), 'models: %s', strjoin(names, ', '));
check(strcmp(kinds{strcmp(names, 'schunk_pg70')}, 'robot') && strcmp(kinds{strcmp(names, 'table')}, 'object'), ...
      'model kinds');
check(~isempty(models(1).description), 'model descriptions');
end

function test_text_round_trip(c, ~)
% Quotes, backslashes, control characters and non-ASCII text survive the JSON encoding both ways.
name = ['quote " backslash \ tab' char(9) 'newline' char(10) 'percent %s end'];
scene = c.createScene(name);
back = c.getScene(scene.id);
c.deleteScene(scene.id);
check(strcmp(scene.name, name) && strcmp(back.summary.name, name), 'name came back as %s', back.summary.name);
end

function test_primitive_objects_and_inertia(c, sid)
m = 2.5;
box = c.addObject(sid, 'box', 'Box', [0.1 0.2 0.3], 'Mass', m, 'Friction', [0.9 0.7], 'Pose', [1 2 3 1 0 0 0]);
check(strcmp(box.id, 'box') && strcmp(box.motion, 'free') && isempty(box.robotId), 'box body');
near(box.inertia, diag([0.2^2 + 0.3^2, 0.1^2 + 0.3^2, 0.1^2 + 0.2^2]) * m / 12, 1e-15, 'box inertia');
near(box.mass, m, 0, 'box mass');
near(box.friction, [0.9 0.7], 0, 'box friction');
near(box.pose, [1 2 3 1 0 0 0], 0, 'box pose');
check(numel(box.collision) == 1 && strcmp(box.collision.type, 'box'), 'box geometry');
near(box.collision.size, [0.1 0.2 0.3], 0, 'box size');

sphere = c.addObject(sid, 'ball', 'Sphere', 0.04, 'Mass', 0.3, 'Static', true);
near(sphere.inertia, eye(3) * 0.4 * 0.3 * 0.04^2, 1e-18, 'sphere inertia');
check(strcmp(sphere.motion, 'static'), 'Static gives a static body, got %s', sphere.motion);
check(strcmp(sphere.collision.type, 'sphere') && sphere.collision.size == 0.04, 'sphere geometry');

r = 0.03;
l = 0.12;
can = c.addObject(sid, 'can', 'Cylinder', [r l], 'Mass', 0.4, 'CenterOfMass', [0 0 0.01]);
side = 0.4 * (3 * r^2 + l^2) / 12;
near(can.inertia, diag([side, side, 0.4 * r^2 / 2]), 1e-18, 'cylinder inertia');
near(can.centerOfMass, [0 0 0.01], 0, 'cylinder centre of mass');
near(can.collision.size, [r l], 0, 'cylinder size');

given = [0.02 0.001 0; 0.001 0.03 0; 0 0 0.04];
explicit = c.addObject(sid, 'explicit', 'Box', [0.1 0.1 0.1], 'Mass', 1, 'Inertia', given);
near(explicit.inertia, given, 0, 'explicit inertia');
scene = c.getScene(sid);
check(isequal(sort({scene.bodies.id}), sort({'box', 'ball', 'can', 'explicit'})), 'getScene bodies');
near(scene.bodies(strcmp({scene.bodies.id}, 'box')).inertia, box.inertia, 0, 'inertia in getScene');
end

function test_builtin_objects(c, sid)
table = c.addObject(sid, 'table', 'Builtin', 'table');
cube = c.addObject(sid, 'cube', 'Builtin', 'cube_5cm', 'Pose', [0 0 0.775 1 0 0 0], 'Friction', [0.5 0.3]);
check(strcmp(table.motion, 'static') && table.mass > 0, 'the table is static with a mass');
check(strcmp(cube.motion, 'free'), 'the cube is free');
near(cube.mass, 0.1, 1e-12, 'cube mass');
near(cube.friction, [0.5 0.3], 0, 'cube friction');
near(cube.pose, [0 0 0.775 1 0 0 0], 1e-15, 'cube pose');
end

function test_inline_mesh_round_trip(c, sid)
[v, t] = boxMesh([0.1 0.06 0.04]);
v = v * diag([1.1 0.9 1.3]) + 0.1;  % values no float32 holds exactly
body = c.addObject(sid, 'mesh', 'Vertices', v, 'Triangles', t, 'Mass', 0.2, 'Inertia', eye(3) * 1e-3);
check(body.triangleCount == 12, 'triangleCount %d', body.triangleCount);
plain = c.getScene(sid);
check(isempty(plain.bodies(1).collision(1).vertices), 'no vertices without IncludeGeometry');
scene = c.getScene(sid, 'IncludeGeometry', true);
g = scene.bodies(1).collision(1);
check(strcmp(g.type, 'mesh'), 'geometry type %s', g.type);
check(isa(g.vertices, 'double') && isequal(size(g.vertices), [8 3]), 'vertices 8-by-3 double');
check(isequal(g.vertices, double(single(v))), 'vertices differ from the float32 values sent');
check(isequal(g.triangles, t), 'triangles (0-based) differ from those sent');
end

function test_mesh_inertia_from_mass(c, sid)
% A box as a mesh, offset from the origin: the divergence theorem gives the box formula and its centre.
edges = [0.125 0.25 0.5];  % exact in float32
offset = [0.5 0.25 -0.125];
[v, t] = boxMesh(edges);
body = c.addObject(sid, 'meshbox', 'Vertices', bsxfun(@plus, v, offset), 'Triangles', t, 'Mass', 3);
expected = diag([edges(2)^2 + edges(3)^2, edges(1)^2 + edges(3)^2, edges(1)^2 + edges(2)^2]) * 3 / 12;
near(body.inertia, expected, 1e-12 * max(expected(:)), 'mesh inertia');
near(body.centerOfMass, offset, 1e-15, 'mesh centroid');
expectError(@() c.addObject(sid, 'inside-out', 'Vertices', v, 'Triangles', fliplr(t), 'Mass', 1), ...
            'graspsim:badArgument', {'closed'});
end

function test_large_request_body(c, sid)
% A 1200-triangle mesh: a request body of about 30 kB, far above small-form limits. Its inertia, computed by
% the client from the mesh, is that of the cylinder it approximates.
r = 0.04;
l = 0.1;
[v, t] = prismMesh(r, l, 300);
body = c.addObject(sid, 'can', 'Vertices', v, 'Triangles', t, 'Mass', 0.5);
check(body.triangleCount == 1200, 'triangleCount %d', body.triangleCount);
side = 0.5 * (3 * r^2 + l^2) / 12;
near(body.inertia, diag([side, side, 0.5 * r^2 / 2]), 1e-3 * side, 'prism inertia');
scene = c.getScene(sid, 'IncludeGeometry', true);
check(isequal(scene.bodies(1).collision(1).vertices, double(single(v))), 'vertices of the big mesh');
check(isequal(scene.bodies(1).collision(1).triangles, t), 'triangles of the big mesh');
end

function test_upload_file_chunks(c, sid)
data = uint8(mod((0:1000) * 7, 256));  % every byte value, 1001 bytes
info = c.uploadFile(sid, 'blobs/bytes.bin', data, 'ChunkSize', 100);
check(strcmp(info.path, 'blobs/bytes.bin') && info.size == 1001, 'file info %s %d', info.path, info.size);
check(strcmp(info.sha256, sha256sum(data)), 'sha256 %s', info.sha256);
empty = c.uploadFile(sid, 'blobs/empty.bin', zeros(0, 1, 'uint8'));
check(empty.size == 0 && strcmp(empty.sha256, 'e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855'), ...
      'empty file');
scene = c.getScene(sid);
files = scene.files;
check(all(ismember({'blobs/bytes.bin', 'blobs/empty.bin'}, {files.path})), 'files listed in the scene');
end

function test_upload_large_file_and_mesh_file(c, sid)
% 5 MiB, above the 4 MiB message limit: six 1 MiB chunks in one HTTP body. Then a local STL file by name.
big = uint8(mod(floor((1:5 * 2^20) * 2.71828), 256));
info = c.uploadFile(sid, 'blobs/big.bin', big);
check(info.size == numel(big) && strcmp(info.sha256, sha256sum(big)), 'big upload');
file = [tempname() '.stl'];
fid = fopen(file, 'w');
[v, t] = boxMesh([0.05 0.05 0.05]);
fwrite(fid, stlBytes(v, t), 'uint8');
fclose(fid);
cleanup = onCleanup(@() delete(file));
stl = c.uploadFile(sid, 'meshes/cube.stl', file);
check(stl.size == 84 + 12 * 50, 'STL size %d', stl.size);
body = c.addObject(sid, 'fromfile', 'MeshFile', 'meshes/cube.stl', 'Mass', 0.1, 'Inertia', eye(3) * 1e-4);
check(body.triangleCount == 12 && strcmp(body.collision(1).type, 'meshFile') ...
      && strcmp(body.collision(1).meshFile, 'meshes/cube.stl'), 'object from an uploaded mesh file');
expectError(@() c.addObject(sid, 'm', 'MeshFile', 'meshes/cube.stl', 'Mass', 0.1), 'graspsim:badArgument', ...
            {'inertia'});
end

function test_urdf_robot_with_files(c, sid)
[v, t] = boxMesh([0.02 0.02 0.02]);
files = struct('path', {'meshes/inline.stl'}, 'data', {stlBytes(v, t)});
added = c.addRobot(sid, 'arm', 'Urdf', twoLinkUrdf('meshes/inline.stl'), 'Files', files, ...
                   'BasePose', [0 0 0.5 1 0 0 0]);
check(strcmp(added.robot.source, 'urdf') && strcmp(added.robot.baseBody, 'arm/base'), 'robot %s', added.robot.source);
check(isequal(sort(added.robot.bodyIds), {'arm/arm'; 'arm/base'}), 'robot body ids');
check(isequal(added.robot.jointIds, {'arm/shoulder'}), 'robot joint ids');
counts = [added.bodies.triangleCount];
check(isequal(sort(counts), [0 12]), 'triangle counts %s', mat2str(counts));
check(strcmp(added.joints(1).type, 'revolute'), 'joint type %s', added.joints(1).type);
near([added.joints(1).lower, added.joints(1).upper], [-1 1], 0, 'joint limits');
near(added.joints(1).axis, [0 0 1], 0, 'joint axis');
c.setJointPositions(sid, 'arm/shoulder', 0.5);
[ids, values] = c.getJointPositions(sid);
check(isequal(ids, {'arm/shoulder'}), 'joint ids');
near(values, 0.5, 1e-15, 'joint position');
end

function test_urdf_robot_by_path(c, sid)
% 'Path' reads a URDF from disk and uploads its meshes itself: package:// against the file's folder and its
% parents (or 'PackageRoots'), relative paths against the file's folder; a second robot uploads nothing new;
% meshes missing on disk are named all at once before anything is sent.
root = tempname();
cleanup = onCleanup(@() rmdir(root, 's'));
mkdir(fullfile(root, 'my_pkg', 'urdf'));
mkdir(fullfile(root, 'my_pkg', 'meshes'));
[v, t] = boxMesh([0.02 0.02 0.02]);
writeBytes(fullfile(root, 'my_pkg', 'meshes', 'arm.stl'), stlBytes(v, t));
[v, t] = boxMesh([0.1 0.1 0.05]);
writeBytes(fullfile(root, 'my_pkg', 'meshes', 'base.stl'), stlBytes(v, t));
inertial = '<inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>';
text = ['<robot name="r"><link name="base">' inertial ...
        '<collision><geometry><mesh filename="package://my_pkg/meshes/base.stl"/></geometry></collision></link>' ...
        '<link name="arm">' inertial ...
        '<collision><geometry><mesh filename="../meshes/arm.stl"/></geometry></collision></link>' ...
        '<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>' ...
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint></robot>'];
file = fullfile(root, 'my_pkg', 'urdf', 'robot.urdf');
writeBytes(file, uint8(text));
added = c.addRobot(sid, 'arm', 'Path', file, 'BasePose', [0 0 0.5 1 0 0 0]);
check(isequal(sort(added.robot.bodyIds), {'arm/arm'; 'arm/base'}), 'robot body ids');
check(isequal(sort([added.bodies.triangleCount]), [12 12]), 'meshes of both links');
scene = c.getScene(sid);
check(isequal(sort({scene.files.path}), {'meshes/arm.stl', 'meshes/base.stl'}), 'uploaded paths %s', ...
      strjoin({scene.files.path}, ', '));
uploaded = c.uploadMissing(sid, {'meshes/arm.stl'}, {fullfile(root, 'my_pkg', 'meshes', 'arm.stl')});
check(isempty(uploaded), 'a file the scene holds with the same SHA-256 is not uploaded again');
added = c.addRobot(sid, 'arm2', 'Path', file, 'PackageRoots', struct('my_pkg', fullfile(root, 'my_pkg')));
check(numel(added.bodies) == 2, 'second robot with PackageRoots');
delete(fullfile(root, 'my_pkg', 'meshes', 'arm.stl'));
delete(fullfile(root, 'my_pkg', 'meshes', 'base.stl'));
before = c.getScene(sid);
expectError(@() c.addRobot(sid, 'arm3', 'Path', file), 'graspsim:missingFiles', ...
            {'package://my_pkg/meshes/base.stl', '../meshes/arm.stl', '2 referenced'});
check(numel(c.getScene(sid).robots) == numel(before.robots), 'nothing added after a missing file');
end

function writeBytes(file, bytes)
fid = fopen(file, 'w');
fwrite(fid, bytes, 'uint8');
fclose(fid);
end

function test_pg70_structure_and_tactile_arrays(c, sid)
base = [0.2 -0.1 1.0 quaternionAbout([1 0.3 0.2], 2.5)];
added = c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', base);
check(strcmp(added.robot.id, 'pg70') && strcmp(added.robot.source, 'builtin:schunk_pg70'), 'robot');
check(isequal(sort(added.robot.bodyIds), {'pg70/base_link'; 'pg70/finger_left'; 'pg70/finger_right'}), 'bodies');
check(isequal(sort(added.robot.tactileArrayIds), {'pg70/pad_left'; 'pg70/pad_right'}), 'pads');
scene = c.getScene(sid);
check(all(strcmp({scene.bodies.motion}, 'articulated')) && all(strcmp({scene.bodies.robotId}, 'pg70')), 'links');
pads = scene.tactileArrays;
check(numel(pads) == 2, '%d tactile arrays', numel(pads));
for k = 1:2
  check(pads(k).rows == 14 && pads(k).cols == 6, 'pad %s is %d x %d, not 14 x 6', pads(k).id, pads(k).rows, pads(k).cols);
  near(pads(k).pitch, 0.0034, 1e-12, 'pad pitch');
  check(ismember(pads(k).bodyId, {'pg70/finger_left', 'pg70/finger_right'}), 'pad body %s', pads(k).bodyId);
  check(pads(k).thickness > 0 && numel(pads(k).origin) == 7, 'pad thickness and origin');
end
joints = scene.joints;
left = joints(strcmp({joints.id}, 'pg70/finger_left_joint'));
right = joints(strcmp({joints.id}, 'pg70/finger_right_joint'));
check(strcmp(left.type, 'prismatic') && isempty(left.mimic.jointId), 'left finger joint');
near([left.lower, left.upper], [0 0.035], 1e-12, 'finger limits');
check(strcmp(right.mimic.jointId, 'pg70/finger_left_joint'), 'right finger mimics the left');
near(right.mimic.multiplier, 1, 1e-12, 'mimic multiplier');
baseBody = scene.bodies(strcmp({scene.bodies.id}, 'pg70/base_link'));
near(baseBody.pose, base, 1e-12, 'base pose');
end

function test_mimic_joint_follows(c, sid)
base = [0.2 -0.1 1.0 quaternionAbout([1 0.3 0.2], 2.5)];
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', base);
fingers = {'pg70/finger_left', 'pg70/finger_right'};
c.setJointPositions(sid, {'pg70/finger_left_joint'}, 0);
[~, closed] = c.getBodyPoses(sid, fingers);
c.setJointPositions(sid, 'pg70/finger_left_joint', 0.02);
[ids, values] = c.getJointPositions(sid, {'pg70/finger_left_joint', 'pg70/finger_right_joint'});
check(isequal(ids, {'pg70/finger_left_joint'; 'pg70/finger_right_joint'}), 'joint ids in request order');
near(values, [0.02; 0.02], 1e-12, 'mimic joint position');
[~, opened] = c.getBodyPoses(sid, fingers);
R = rotationMatrix(base(4:7));
moveLeft = R.' * (opened(1, 1:3) - closed(1, 1:3)).';  % in the gripper frame
moveRight = R.' * (opened(2, 1:3) - closed(2, 1:3)).';
s = sign(moveLeft(2));
near(moveLeft.', [0 s * 0.02 0], 1e-9, 'left finger move');
near(moveRight.', [0 -s * 0.02 0], 1e-9, 'right finger move');
near(opened(:, 4:7), closed(:, 4:7), 1e-12, 'finger orientations');
end

function test_pose_round_trip(c, sid)
ids = {'a', 'b', 'c'};
for k = 1:3
  c.addObject(sid, ids{k}, 'Sphere', 0.01, 'Mass', 0.1);
end
poses = [10 * sin([1:3; 4:6; 7:9]), zeros(3, 4)];  % arbitrary numbers with every digit used
for k = 1:3
  poses(k, 4:7) = quaternionAbout(cos(k * [1.1 2.3 3.7]), 1 + k);
end
poses(2, 1:3) = [1e-300, -123456.789012345678, 0.1];  % a tiny and a big number keep every digit
r1 = c.setBodyPoses(sid, ids, poses);
[back, got, r2, t] = c.getBodyPoses(sid, {'c', 'a', 'b'});
check(isequal(back, {'c'; 'a'; 'b'}), 'ids in request order');
near(got, poses([3 1 2], :), 1e-12, 'poses');
check(got(3, 1) == 1e-300, 'a tiny coordinate became %g', got(3, 1));
check(r2 == r1 && r1 >= 1 && t == 0, 'revision %g then %g, time %g', r1, r2, t);
r3 = c.setBodyPoses(sid, 'b', [0 0 1 1 0 0 0]);
check(r3 > r1, 'revision increases');
[everyId, everyPose] = c.getBodyPoses(sid);
check(isequal(sort(everyId), {'a'; 'b'; 'c'}) && size(everyPose, 1) == 3, 'every body without ids');
near(everyPose(strcmp(everyId, 'b'), :), [0 0 1 1 0 0 0], 0, 'single pose');
end

function test_joint_positions(c, sid)
c.addRobot(sid, 'arm', 'Urdf', twoLinkUrdf(''));
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70');
r = c.setJointPositions(sid, {'arm/shoulder', 'pg70/finger_left_joint'}, [-0.75; 0.0123456789012345]);
[ids, values, r2] = c.getJointPositions(sid);
check(numel(ids) == 3 && r2 == r && size(values, 2) == 1, 'every joint, values N-by-1');
near(values(strcmp(ids, 'arm/shoulder')), -0.75, 1e-15, 'arm');
near(values(strcmp(ids, 'pg70/finger_left_joint')), 0.0123456789012345, 1e-15, 'finger');
end

function test_watch_scene(c, sid)
c.addObject(sid, 'cube', 'Builtin', 'cube_5cm', 'Pose', [0.1 0.2 0.3 0 0 0 1]);
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 1 0 1 0 0]);
c.setJointPositions(sid, 'pg70/finger_left_joint', 0.01);
[ids, poses, revision] = c.getBodyPoses(sid);
snap = c.watchScene(sid, 1);
check(numel(snap) == 1 && isa(snap.sequence, 'double') && snap.revision == revision, 'one snapshot');
check(isequal(sort(snap.bodyIds), sort(ids)) && isequal(size(snap.poses), [numel(ids) 7]), 'snapshot bodies');
for k = 1:numel(ids)
  near(snap.poses(strcmp(snap.bodyIds, ids{k}), :), poses(k, :), 1e-12, ['snapshot pose of ' ids{k}]);
end
check(isequal(sort(snap.jointIds), {'pg70/finger_left_joint'; 'pg70/finger_right_joint'}), 'snapshot joints');
near(snap.jointPositions, [0.01; 0.01], 1e-12, 'snapshot joint positions');
% Nothing changes: of 3 snapshots only the first arrives within the timeout, and watchScene returns it.
few = c.watchScene(sid, 3, 'Timeout', 1);
check(numel(few) == 1 && few(1).revision == revision, 'watchScene after its timeout gave %d snapshots', numel(few));
expectError(@() c.watchScene('no-such-scene', 1), 'graspsim:NOT_FOUND', {'no-such-scene'});
end

function test_remove_body(c, sid)
c.addObject(sid, 'cube', 'Builtin', 'cube_5cm');
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70');
removed = c.removeBody(sid, 'pg70');
check(isequal(sort(removed), {'pg70/base_link'; 'pg70/finger_left'; 'pg70/finger_right'}), 'removed robot bodies');
check(isequal(c.removeBody(sid, 'cube'), {'cube'}), 'removed object');
scene = c.getScene(sid);
check(isempty(scene.bodies) && isempty(scene.joints) && isempty(scene.tactileArrays), 'scene empty after removals');
expectError(@() c.removeBody(sid, 'cube'), 'graspsim:NOT_FOUND', {'cube'});
end

function test_generic_call(c, sid)
scene = c.call('SceneService', 'GetScene', struct('scene_id', sid));
check(strcmp(scene.summary.id, sid) && ischar(scene.summary.revision), 'GetScene through call (uint64 as char)');
full = c.call('graspsim.v1.SceneService', 'CreateScene', '{"name": "raw json"}');
c.deleteScene(full.summary.id);
check(strcmp(full.summary.name, 'raw json'), 'raw JSON request');
body = c.call('SceneService', 'AddObject', struct('scene_id', sid, 'name', 'cube', 'builtin', 'cube_5cm'));
check(strcmp(body.motion, 'BODY_MOTION_FREE'), 'enums by name: %s', body.motion);
poses = c.call('SceneService', 'GetBodyPoses', struct('scene_id', sid, 'body_ids', {{'cube'}}));
check(numel(poses.poses) == 1 && strcmp(poses.poses(1).body_id, 'cube'), 'one-element repeated field as a cell');
snaps = c.call('SceneService', 'WatchScene', struct('scene_id', sid), 'MaxMessages', 1);
check(iscell(snaps) && numel(snaps) == 1 && isfield(snaps{1}, 'body_poses'), 'server stream through call');
snaps = c.call('SceneService', 'WatchScene', struct('scene_id', sid), 'MaxMessages', 5, 'MaxSeconds', 0.5);
check(numel(snaps) == 1, 'MaxSeconds ends a stream: %d messages', numel(snaps));
chunks = {struct('header', struct('scene_id', sid, 'path', 'x.txt', 'total_size', 3, ...
                                  'sha256', sha256sum(uint8('abc'))), 'data', 'YWJj')};
info = c.call('SceneService', 'UploadFile', chunks);
check(strcmp(info.size, '3'), 'client stream through call');
end

function test_error_nan_pose(c, sid)
c.addObject(sid, 'cube', 'Builtin', 'cube_5cm');
before = c.getScene(sid, 'IncludeGeometry', true);
err = expectError(@() c.addObject(sid, 'new', 'Box', [0.1 0.1 0.1], 'Mass', 1, 'Pose', [NaN 0 0 1 0 0 0]), ...
                  'graspsim:INVALID_ARGUMENT', {'pose.position', 'nan'});
check(~isempty(strfind(err.message, 'pose')), 'message names the pose');
expectError(@() c.addObject(sid, 'new', 'Box', [0.1 Inf 0.1], 'Mass', 1), 'graspsim:INVALID_ARGUMENT', ...
            {'geometry.box.size', 'inf'});
% All or nothing: a batch with one bad pose changes nothing.
expectError(@() c.setBodyPoses(sid, {'cube', 'cube'}, [0 0 2 1 0 0 0; 0 NaN 0 1 0 0 0]), ...
            'graspsim:INVALID_ARGUMENT', {'pose', 'nan'});
after = c.getScene(sid, 'IncludeGeometry', true);
check(isequal(before.bodies, after.bodies) && before.summary.revision == after.summary.revision, ...
      'a rejected request changed the scene');
end

function test_error_bad_quaternion(c, sid)
expectError(@() c.addObject(sid, 'q', 'Builtin', 'cube_5cm', 'Pose', [0 0 1 2 0 0 0]), ...
            'graspsim:INVALID_ARGUMENT', {'pose.orientation', 'norm 2'});
end

function test_error_unknown_scene(c, sid)
expectError(@() c.getScene('no-such-scene'), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.addObject('no-such-scene', 'x', 'Builtin', 'cube_5cm'), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.deleteScene('no-such-scene'), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.addObject(sid, 'x', 'Builtin', 'no_such_model'), 'graspsim:NOT_FOUND', ...
            {'no_such_model'});
end

function test_error_duplicate_name(c, sid)
c.addObject(sid, 'cube', 'Builtin', 'cube_5cm');
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70');
expectError(@() c.addObject(sid, 'cube', 'Box', [0.1 0.1 0.1], 'Mass', 1), 'graspsim:ALREADY_EXISTS', {'cube'});
expectError(@() c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70'), 'graspsim:ALREADY_EXISTS', {'pg70'});
end

function test_error_joint_outside_limits(c, sid)
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70');
c.setJointPositions(sid, 'pg70/finger_left_joint', 0.01);
expectError(@() c.setJointPositions(sid, 'pg70/finger_left_joint', 0.5), 'graspsim:INVALID_ARGUMENT', ...
            {'pg70/finger_left_joint', '0.5', 'limits'});
expectError(@() c.setJointPositions(sid, 'pg70/finger_right_joint', 0.02), 'graspsim:INVALID_ARGUMENT', ...
            {'mimics'});
expectError(@() c.setJointPositions(sid, 'pg70/no_joint', 0.02), 'graspsim:NOT_FOUND', {'pg70/no_joint'});
[~, values] = c.getJointPositions(sid, 'pg70/finger_left_joint');
near(values, 0.01, 0, 'joint unchanged after rejected requests');
end

function test_body_and_joint_velocity_fields(c, sid)
empty = c.getScene(sid);
check(isfield(empty.bodies, 'velocity') && isfield(empty.bodies, 'sleeping') && isfield(empty.joints, 'velocity'), ...
      'empty arrays have the velocity fields');
cube = c.addObject(sid, 'cube', 'Builtin', 'cube_5cm', 'Pose', [0 0 1 1 0 0 0]);
near(cube.velocity, zeros(1, 6), 0, 'velocity of a new body');
check(islogical(cube.sleeping) && ~cube.sleeping, 'a new body is awake');
check(isstruct(cube.contact) && cube.contact.stiffness == 0, 'material contact parameters (0 = scene default)');
added = c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70');
near([added.joints.velocity], [0 0], 0, 'joint velocities of a new robot');
end

function test_simulation_cube_settles(c, sid)
% A 5 cm cube dropped from 7.5 cm above the built-in table (top at 0.75 m) lands and comes to rest.
tableTop = 0.75;
half = 0.025;
c.addObject(sid, 'table', 'Builtin', 'table');
c.addObject(sid, 'cube', 'Box', [0.05 0.05 0.05], 'Mass', 0.1, 'Pose', [0 0 tableTop + half + 0.075, 1 0 0 0]);
params = c.getSimulationParams(sid);
dt = params.timeStep;
revision = c.getScene(sid).summary.revision;
% Free fall for 0.1 s (the cube needs 0.124 s to fall the 7.5 cm): v = -g t.
falling = c.stepSimulation(sid, 'Duration', 0.1);
check(falling.steps == round(0.1 / dt) && falling.awakeBodies == 1 && falling.contacts == 0, ...
      'falling: %d steps, %d awake, %d contacts', falling.steps, falling.awakeBodies, falling.contacts);
check(isa(falling.revision, 'double') && falling.revision > revision, 'revision %g after %g', falling.revision, ...
      revision);
cube = sceneBody(c, sid, 'cube');
near(cube.velocity, [0 0 -9.81 * 0.1, 0 0 0], 1e-6, 'free-fall velocity');
check(~cube.sleeping, 'a falling cube is awake');
result = c.stepSimulation(sid, 'Duration', 1.4);
check(result.steps == round(1.4 / dt), '%d steps for 1.4 s of %g s', result.steps, dt);
near(result.time - falling.time, result.steps * dt, 1e-9, 'time advanced by steps * time_step');
near(result.time, 1.5, 1e-9, 'simulation time');
cube = sceneBody(c, sid, 'cube');
near(cube.pose(3), tableTop + half, 1e-3, 'resting height');
check(cube.pose(3) <= tableTop + half + 1e-6, 'the cube floats at %.6f m', cube.pose(3));
near(cube.pose(1:2), [0 0], 1e-3, 'resting place');
check(abs(cube.pose(4)) > 1 - 1e-6, 'the cube tipped: %s', mat2str(cube.pose(4:7), 6));
check(norm(cube.velocity) < 1e-3, 'still moving at rest: %s', mat2str(cube.velocity, 4));
check(cube.sleeping && result.awakeBodies == 0, 'the cube at rest sleeps (%d awake)', result.awakeBodies);
[~, poses, ~, time] = c.getBodyPoses(sid, 'cube');
near(poses, cube.pose, 0, 'getBodyPoses after stepping');
near(time, result.time, 0, 'getBodyPoses time');
end

function test_simulation_step_forms(c, sid)
c.addObject(sid, 'ball', 'Sphere', 0.02, 'Mass', 0.1, 'Pose', [0 0 10 1 0 0 0]);
c.setSimulationParams(sid, 'TimeStep', 2e-3);
r = c.stepSimulation(sid, 'Steps', 10);
check(r.steps == 10, 'Steps: %d steps', r.steps);
near(r.time, 0.02, 1e-12, 'time after 10 steps');
r = c.stepSimulation(sid, 0.1);  % a plain number is a duration
check(r.steps == 50, 'a plain duration of 0.1 s: %d steps', r.steps);
near(r.time, 0.12, 1e-12, 'time after the plain duration');
r = c.stepSimulation(sid, 'duration', 0.011);  % option names are case-insensitive; rounded to whole steps
check(r.steps == 5 || r.steps == 6, 'Duration 0.011 s of 2 ms steps: %d steps', r.steps);
t = r.time;
r = c.stepSimulation(sid, 'UntilTime', 0.5);
check(r.steps == round((0.5 - t) / 2e-3), 'UntilTime: %d steps from %g s', r.steps, t);
near(r.time, 0.5, 1e-9, 'time after UntilTime');
r = c.stepSimulation(sid, 'Steps', 0);
check(r.steps == 0 && r.time == c.getScene(sid).summary.time, 'zero steps');
near(r.time, 0.5, 1e-9, 'zero steps keep the time');
ball = sceneBody(c, sid, 'ball');
near(ball.velocity(3), -9.81 * 0.5, 1e-9, 'free-fall velocity after 0.5 s');
expectError(@() c.stepSimulation(sid, 'UntilTime', 0.1), 'graspsim:INVALID_ARGUMENT', {'until_time', '0.1', 'before'});
expectError(@() c.stepSimulation(sid, 'Duration', -1), 'graspsim:INVALID_ARGUMENT', {'duration', '-1'});
expectError(@() c.stepSimulation(sid, NaN), 'graspsim:INVALID_ARGUMENT', {'duration', 'nan'});
expectError(@() c.stepSimulation('no-such-scene', 'Steps', 1), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.stepSimulation(sid), 'graspsim:badArgument', {'exactly one'});
expectError(@() c.stepSimulation(sid, 'Steps', 1, 'Duration', 1), 'graspsim:badArgument', {'exactly one'});
expectError(@() c.stepSimulation(sid, 'Steps', 2.5), 'graspsim:badArgument', {'Steps', 'whole'});
expectError(@() c.stepSimulation(sid, 'Seconds', 1), 'graspsim:badArgument', {'seconds'});
near(c.getScene(sid).summary.time, 0.5, 1e-9, 'refused steps change nothing');
% The raw call shows the server's own check that one amount is given.
expectError(@() c.call('SceneService', 'StepSimulation', struct('scene_id', sid)), 'graspsim:INVALID_ARGUMENT', ...
            {'amount'});
end

function test_simulation_params_round_trip(c, sid)
defaults = c.getSimulationParams(sid);
near(defaults.timeStep, 1e-3, 1e-15, 'default time step');
check(defaults.substeps == 1 && strcmp(defaults.integrator, 'linearly_implicit_euler'), 'default substeps %d, %s', ...
      defaults.substeps, defaults.integrator);
near(defaults.gravity, [0 0 -9.81], 1e-12, 'default gravity');
check(defaults.contact.stiffness > 0 && defaults.contact.damping > 0 && defaults.sampleSpacing > 0 ...
      && defaults.sleepSpeed > 0 && defaults.sleepTime > 0, 'defaults filled in');
contact = struct('stiffness', 2e4, 'stribeckVelocity', 0.02);
applied = c.setSimulationParams(sid, 'TimeStep', 5e-4, 'Substeps', 2, 'Integrator', 'semi_implicit_euler', ...
                            'Gravity', [0.1 0 -1.62], 'Contact', contact, 'SampleSpacing', 0.004, ...
                            'SleepSpeed', 0.002, 'sleep_time', 0.25);
got = c.getSimulationParams(sid);
check(isequal(applied, got), 'setSimulationParams returned other parameters than getSimulationParams');
near([got.timeStep, got.substeps, got.sampleSpacing, got.sleepSpeed, got.sleepTime], [5e-4, 2, 0.004, 0.002, 0.25], ...
     1e-15, 'scalar parameters');
check(strcmp(got.integrator, 'semi_implicit_euler'), 'integrator %s', got.integrator);
near(got.gravity, [0.1 0 -1.62], 1e-15, 'gravity');
near([got.contact.stiffness, got.contact.stribeckVelocity], [2e4, 0.02], 1e-12, 'contact');
near(got.contact.damping, defaults.contact.damping, 0, 'a contact field not given keeps its default');
% The struct form takes getSimulationParams' struct back: change one field, keep the rest.
got.integrator = 'velocity_verlet';
got.gravity = [0 0 0];  % no gravity is a value, not the default
back = c.setSimulationParams(sid, got);
check(isequal(back, got), 'struct round trip: %s', evalc('disp(back)'));
% Fields not given take the server's defaults, as in the Python client.
partial = c.setSimulationParams(sid, 'TimeStep', 2e-3);
expected = defaults;
expected.timeStep = 2e-3;
check(isequal(partial, expected), 'parameters not given should be the defaults');
check(isequal(c.setSimulationParams(sid), defaults), 'no parameters = the defaults');
check(isequal(c.setSimulationParams(sid, struct('timeStep', [], 'integrator', 'INTEGRATOR_VELOCITY_VERLET')), ...
              setfield(defaults, 'integrator', 'velocity_verlet')), 'empty fields are not given');  %#ok<SFLD>
end

function test_error_simulation_params(c, sid)
before = c.setSimulationParams(sid, 'TimeStep', 5e-4, 'Integrator', 'velocity_verlet');
expectError(@() c.setSimulationParams(sid, 'TimeStep', -1), 'graspsim:INVALID_ARGUMENT', {'params.time_step', '-1'});
expectError(@() c.setSimulationParams(sid, 'Substeps', 5000), 'graspsim:INVALID_ARGUMENT', {'params.substeps'});
expectError(@() c.setSimulationParams(sid, 'Contact', struct('stiffness', NaN)), 'graspsim:INVALID_ARGUMENT', ...
            {'params.contact.stiffness'});
expectError(@() c.setSimulationParams(sid, 'SleepSpeed', -1), 'graspsim:INVALID_ARGUMENT', {'params.sleep_speed'});
expectError(@() c.setSimulationParams('no-such-scene', 'TimeStep', 1e-3), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.getSimulationParams('no-such-scene'), 'graspsim:NOT_FOUND', {'no-such-scene'});
check(isequal(c.getSimulationParams(sid), before), 'a refused setSimulationParams changed the parameters');
expectError(@() c.setSimulationParams(sid, 'Integrator', 'rk4'), 'graspsim:badArgument', ...
            {'linearly_implicit_euler', 'semi_implicit_euler', 'velocity_verlet'});
expectError(@() c.setSimulationParams(sid, 'TimeStepp', 1e-3), 'graspsim:badArgument', {'TimeStepp', 'TimeStep'});
expectError(@() c.setSimulationParams(sid, 'Gravity', [0 -9.81]), 'graspsim:badArgument', {'Gravity', '3'});
expectError(@() c.setSimulationParams(sid, 'Contact', struct('stiffnes', 1)), 'graspsim:badArgument', {'stiffnes'});
expectError(@() c.setSimulationParams(sid, 'Substeps', 1.5), 'graspsim:badArgument', {'Substeps'});
expectError(@() c.setSimulationParams(sid, 'TimeStep'), 'graspsim:badArgument', {'name-value'});
check(isequal(c.getSimulationParams(sid), before), 'a refused client call changed the parameters');
end

function test_actuator_moves_fingers(c, sid)
left = 'pg70/finger_left_joint';
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 1 1 0 0 0]);
c.setJointPositions(sid, left, 0.01);
c.setActuator(sid, left, 'velocity', 0.02);  % open at 2 cm/s
c.stepSimulation(sid, 'Duration', 0.4);
[opened, velocity, follower] = fingerState(c, sid);
check(opened > 0.01 + 0.004 && opened < 0.01 + 0.008, 'opening at 0.02 m/s for 0.4 s: %.5f m', opened);
near(velocity, 0.02, 1e-3, 'finger velocity in velocity mode');
near(follower, opened, 1e-12, 'the mimic finger follows');
c.setActuator(sid, left, 'Velocity', -0.02, 2);  % close, current limited to 2 A
c.stepSimulation(sid, 'Duration', 0.4);
[closed, velocity] = fingerState(c, sid);
check(closed < opened - 0.004, 'closing at -0.02 m/s for 0.4 s: %.5f m after %.5f m', closed, opened);
near(velocity, -0.02, 1e-3, 'finger velocity closing');
c.setActuator(sid, left, 'position', 0.025);
c.stepSimulation(sid, 'Duration', 1.0);
[position, velocity] = fingerState(c, sid);
near(position, 0.025, 1e-4, 'position mode reaches its target');
near(velocity, 0, 1e-3, 'at rest at the target');
c.setActuator(sid, left, 'off');
c.stepSimulation(sid, 'Steps', 10);
near(fingerState(c, sid), position, 1e-4, 'no drive: the finger stays');
end

function test_error_actuator(c, sid)
left = 'pg70/finger_left_joint';
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70');
expectError(@() c.setActuator(sid, 'pg70/nope', 'velocity', 0.01), 'graspsim:NOT_FOUND', ...
            {'pg70/nope', 'commands[0].joint_id'});
expectError(@() c.setActuator(sid, 'pg70/finger_right_joint', 'velocity', 0.01), 'graspsim:INVALID_ARGUMENT', ...
            {'pg70/finger_right_joint', 'mimic'});
expectError(@() c.setActuator(sid, left, 'position', Inf), 'graspsim:INVALID_ARGUMENT', {'commands[0].value'});
expectError(@() c.setActuator(sid, left, 'velocity', 0.01, -1), 'graspsim:INVALID_ARGUMENT', ...
            {'commands[0].current_limit', '-1'});
expectError(@() c.setActuator('no-such-scene', left, 'velocity', 0.01), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.setActuator(sid, left, 'torque', 1), 'graspsim:badArgument', ...
            {'off', 'voltage', 'velocity', 'position'});
expectError(@() c.setActuator(sid, left, 'velocity', [1 2]), 'graspsim:badArgument', {'value'});
c.stepSimulation(sid, 'Steps', 50);
[~, values] = c.getJointPositions(sid, left);
check(values == 0, 'a refused command installed a drive: the finger moved to %g m', values);
end

function test_tactile_sample_untouched(c, sid)
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 1 1 0 0 0]);
for pad = {'pg70/pad_left', 'pg70/pad_right'}
  r = c.sampleSensor(sid, pad{1});
  check(strcmp(r.sensorId, pad{1}) && strcmp(r.kind, 'tactile'), 'reading of %s: %s %s', pad{1}, r.sensorId, r.kind);
  check(r.time == 0 && r.rows == 14 && r.cols == 6, '%s: t %g, %d x %d', pad{1}, r.time, r.rows, r.cols);
  check(isa(r.intensities, 'double') && isequal(r.intensities, zeros(14, 6)), 'intensities of %s', pad{1});
  check(isa(r.forces, 'double') && isequal(r.forces, zeros(14, 6, 3)), 'forces of %s', pad{1});
  check(r.intensitySum == 0 && isequal(r.forceSum, [0 0 0]), 'sums of %s', pad{1});
  check(isempty(r.fingerDistance) && isempty(r.motorCurrent), 'gripper fields of a tactile reading');
end
end

function test_tactile_image_png(c, sid)
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 1 1 0 0 0]);
[png, width, height] = c.tactileImage(sid, 'pg70/pad_left', 10);
check(isa(png, 'uint8') && size(png, 1) == 1 && numel(png) > 33, 'png: %s %s', class(png), mat2str(size(png)));
check(isequal(png(1:8), uint8([137 80 78 71 13 10 26 10])), 'PNG signature: %s', mat2str(png(1:8)));
check(isequal(char(png(13:16)), 'IHDR'), 'the first chunk is %s', char(png(13:16)));
bigEndian = @(b) sum(double(b) .* 256 .^ (3:-1:0));
check(bigEndian(png(17:20)) == 60 && bigEndian(png(21:24)) == 140, 'IHDR size %d x %d, expected 60 x 140', ...
      bigEndian(png(17:20)), bigEndian(png(21:24)));
check(width == 60 && height == 140, 'reported size %d x %d', width, height);
[png, width, height] = c.tactileImage(sid, 'pg70/pad_right');  % the default scale, 20
check(width == 120 && height == 280 && bigEndian(png(17:20)) == 120, 'default scale: %d x %d', width, height);
end

function test_gripper_reading(c, sid)
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 1 1 0 0 0]);
g = c.sampleSensor(sid, 'pg70/gripper');
check(strcmp(g.kind, 'gripper') && strcmp(g.sensorId, 'pg70/gripper') && isempty(g.intensities), 'gripper reading');
check(g.fingerDistance == 0 && g.motorCurrent == 0 && g.fingerVelocity == 0, 'closed and undriven');
c.setJointPositions(sid, 'pg70/finger_left_joint', 0.01);
g = c.sampleSensor(sid, 'pg70/gripper');
near(g.fingerDistance, 0.02, 1e-12, 'finger distance (both fingers at 0.01 m)');
check(g.motorCurrent == 0 && g.fingerVelocity == 0 && g.time == 0, 'set, not driven');
end

function test_tactile_grasp_reading(c, sid)
% The cell of clients/python/examples/tactile_cycle.py, its fingertips lowered only 12 mm past the cube's top:
% the cube touches a band of rows at one end of each pad, across all its columns.
[gripper, cube] = buildCell(c, sid);
c.setJointPositions(sid, {[gripper '/z_axis'], [gripper '/finger_left_joint']}, [-0.105, 0.03]);
c.setActuator(sid, [gripper '/z_axis'], 'position', -0.105);  % undriven, the axis would slide down
c.setActuator(sid, [gripper '/finger_left_joint'], 'velocity', -0.02, 1.0);
c.stepSimulation(sid, 'Duration', 1.5);
[~, pose] = c.getBodyPoses(sid, cube);
near(pose(1:3), [0 0 0.775], 1e-3, 'the squeezed cube stays put');
sums = zeros(1, 2);
pads = {[gripper '/pad_left'], [gripper '/pad_right']};
for k = 1:2
  r = c.sampleSensor(sid, pads{k});
  near(r.time, 1.5, 1e-9, 'reading time');
  touched = r.intensities > 0;
  rows = find(any(touched, 2));
  check(~isempty(rows) && numel(rows) < r.rows && all(all(touched(rows, :))), ...
        '%s: touched texels\n%s', pads{k}, mat2str(r.intensities));
  check(all(diff(rows) == 1) && (rows(1) == 1 || rows(end) == r.rows), '%s: rows %s are not a band at an end', ...
        pads{k}, mat2str(rows));
  near(sum(r.intensities(:)), r.intensitySum, 0, 'intensity sum');
  total = reshape(sum(sum(r.forces, 1), 2), 1, 3);
  near(total, r.forceSum, 1e-3 * max(1, norm(r.forceSum)), 'force sum');
  check(abs(r.forceSum(3)) > 1 && all(all(r.forces(:, :, 3) .* touched ~= 0 | ~touched)), ...
        '%s: normal force %g N', pads{k}, r.forceSum(3));
  sums(k) = r.intensitySum;
end
check(abs(sums(1) - sums(2)) <= 0.02 * mean(sums), 'pad sums %d and %d differ', sums(1), sums(2));
g = c.sampleSensor(sid, [gripper '/gripper']);
check(g.fingerDistance > 0.04 && g.fingerDistance < 0.05, 'fingers %g m apart on a 5 cm cube', g.fingerDistance);
% The left finger's joint is a force/torque sensor: along the finger axis (its frame's y, closing = -y) it
% transmits the grip force that the left pad feels as its normal force.
left = c.sampleSensor(sid, pads{1});
ft = c.sampleSensor(sid, [gripper '/finger_left_joint']);
check(strcmp(ft.kind, 'forceTorque') && isempty(ft.intensities) && numel(ft.torque) == 3, 'force/torque reading');
near(ft.time, 1.5, 1e-9, 'force/torque reading time');
near(-ft.force(2), abs(left.forceSum(3)), 0.05 * abs(left.forceSum(3)), 'finger joint force vs the pad''s');
end

function test_stream_sensors(c, sid)
c.addRobot(sid, 'pg70', 'Builtin', 'schunk_pg70', 'BasePose', [0 0 1 1 0 0 0]);
ids = {'pg70/pad_left', 'pg70/gripper'};
first = c.streamSensors(sid, ids, 50);  % one round: one reading per id, at once
check(numel(first) == 2 && isequal({first.sensorId}, ids), 'first round: %s', strjoin({first.sensorId}, ', '));
check(isequal({first.kind}, {'tactile', 'gripper'}) && all([first.time] == 0), 'first round kinds and times');
check(isequal(first(1).intensities, zeros(14, 6)) && first(2).fingerDistance == 0, 'first round values');
c.setJointPositions(sid, 'pg70/finger_left_joint', 0.015);
c.stepSimulation(sid, 'Duration', 0.05);
later = c.streamSensors(sid, ids, 50, 'MaxMessages', 2);
check(numel(later) == 2 && isequal({later.sensorId}, ids), 'second stream: %d readings', numel(later));
near([later.time], [0.05 0.05], 1e-9, 'times after stepping');
check(all([later.time] > [first.time]), 'the stream''s times did not increase');
near(later(2).fingerDistance, 0.03, 1e-6, 'streamed finger distance');
% Nothing changes: of 4 readings only the first round arrives within MaxSeconds.
few = c.streamSensors(sid, 'pg70/gripper', 20, 'MaxMessages', 4, 'MaxSeconds', 1);
check(numel(few) == 1 && strcmp(few.sensorId, 'pg70/gripper'), 'after MaxSeconds: %d readings', numel(few));
end

function test_work_cycle_lifts_cube(c, sid)
[gripper, cube] = buildCell(c, sid);
lift = 0.04;
r = c.runWorkCycle(sid, gripper, cube, 'TactileSetpoint', 30000, 'LiftHeight', lift, 'HoldTime', 0.2, ...
                   'FrameRateHz', 100);
n = numel(r.time);
check(n > 10 && all(diff(r.time) > 0), '%d frames, times increasing', n);
check(isequal(unique(r.stage, 'stable'), {'approach'; 'grasp'; 'lift'; 'hold'; 'move_down'; 'release'; 'done'}), ...
      'stages %s', strjoin(unique(r.stage, 'stable').', ' > '));
check(isequal(size(r.leftImages), [14 6 n]) && isequal(size(r.rightImages), [14 6 n]), 'image stack %s', ...
      mat2str(size(r.leftImages)));
check(isequal(size(r.objectPosition), [n 3]) && isequal(size(r.leftSum), [n 1]) && iscellstr(r.stage), 'shapes');
near(reshape(sum(sum(r.leftImages, 1), 2), [], 1), r.leftSum, 0, 'left images vs sums');
check(strcmp(r.leftId, [gripper '/pad_left']) && strcmp(r.rightId, [gripper '/pad_right']) && ...
      strcmp(r.gripperSensorId, [gripper '/gripper']), 'sensor ids');
check(r.tactileSetpoint == 30000 && r.liftHeight == lift && r.coverage == 1, 'settings with defaults');
check(r.leftSum(1) == 0 && r.rightSum(1) == 0 && r.leftSum(end) == 0, 'no contact before the grasp and after release');
holding = strcmp(r.stage, 'hold');
carried = find(strcmp(r.stage, 'lift') | holding);
lifted = r.objectPosition(carried(end), 3) - r.objectPosition(carried(1), 3);
near(lifted, lift, 0.002, 'the cube rose by the lift height');
average = (r.leftSum(holding) + r.rightSum(holding)) / 2;
check(all(average > 0) && max(abs(r.leftSum(holding) - r.rightSum(holding)) ./ average) <= 0.02, ...
      'pad sums while holding differ by more than 2 %%');
near(average, 30000 * ones(size(average)), 0.1 * 30000, 'held at the set-point');
near(r.objectPosition(end, 3), r.objectPosition(1, 3), 0.002, 'the cube put back');
check(all(r.fingerDistance(holding) > 0.04 & r.fingerDistance(holding) < 0.05), 'fingers on the cube while holding');
check(all(r.currentLimit > 0) && all(r.axisPosition <= 1e-9), 'current limits and axis positions');
end

function test_error_tactile(c, sid)
[gripper, cube] = buildCell(c, sid);
expectError(@() c.sampleSensor(sid, 'cell/nope'), 'graspsim:NOT_FOUND', {'cell/nope', 'sensor_id', 'cell/pad_left'});
expectError(@() c.sampleSensor('no-such-scene', 'cell/gripper'), 'graspsim:NOT_FOUND', {'no-such-scene'});
expectError(@() c.tactileImage(sid, 'cell/nope', 10), 'graspsim:NOT_FOUND', {'cell/nope'});
expectError(@() c.tactileImage(sid, 'cell/gripper'), 'graspsim:INVALID_ARGUMENT', {'cell/gripper', 'tactile'});
expectError(@() c.tactileImage(sid, 'cell/pad_left', 2.5), 'graspsim:badArgument', {'scale'});
expectError(@() c.streamSensors(sid, {'cell/gripper', 'cell/nope'}, 10), 'graspsim:NOT_FOUND', ...
            {'cell/nope', 'sensor_ids[1]'});
expectError(@() c.streamSensors(sid, 'cell/gripper', 0), 'graspsim:INVALID_ARGUMENT', {'rate_hz'});
expectError(@() c.streamSensors(sid, 'cell/gripper'), 'graspsim:badArgument', {'rateHz'});
expectError(@() c.streamSensors(sid, 'cell/gripper', 10, 'MaxMessages', 0), 'graspsim:badArgument', {'MaxMessages'});
expectError(@() c.runWorkCycle(sid, gripper, cube, 'Coverage', 1.5), 'graspsim:INVALID_ARGUMENT', {'coverage', '1.5'});
expectError(@() c.runWorkCycle(sid, gripper, 'no_cube'), 'graspsim:NOT_FOUND', {'no_cube'});
expectError(@() c.runWorkCycle(sid, gripper, cube, 'Speed', 2), 'graspsim:badArgument', {'speed'});
[~, pose] = c.getBodyPoses(sid, cube);
near(pose, [0 0 0.775 1 0 0 0], 1e-9, 'a refused work cycle moved the cube');
end

function test_recording_falling_box(c, sid)
% RecordingService (issue 25, docs/recording.md): a box falling for 0.2 s in four steps, recorded into an MCAP
% file, downloaded, replayed into a new scene and seeked to its last frame.
name = sprintf('octave-%s.mcap', regexprep(sid, '[^A-Za-z0-9_-]', '_'));
listing = c.listMethods();
services = listing.services;
check(any(strcmp({services.name}, 'graspsim.v1.RecordingService')), 'the gateway does not serve RecordingService: %s', ...
      strjoin({services.name}, ', '));
c.addObject(sid, 'box', 'Box', [0.05 0.05 0.05], 'Mass', 0.1, 'Pose', [0 0 1 1 0 0 0]);
started = c.startRecording(sid, name);
check(strcmp(started.name, name) && strcmp(started.sceneId, sid) && started.active, ...
      'started: name %s, scene %s, active %d', started.name, started.sceneId, started.active);
try
  for k = 1:4
    c.stepSimulation(sid, 'Duration', 0.05);
  end
  listed = c.listRecordings();
  row = listed(strcmp({listed.name}, name));
  check(numel(row) == 1 && row.active, 'listRecordings while recording: %d rows named %s', numel(row), name);
catch err
  try
    c.stopRecording(sid);
  catch  %#ok<CTCH> the test's own error is the one to report
  end
  rethrow(err);
end
stopped = c.stopRecording(sid);
check(strcmp(stopped.name, name) && strcmp(stopped.sceneId, sid) && ~stopped.active, ...
      'stopped: name %s, scene %s, active %d', stopped.name, stopped.sceneId, stopped.active);
check(stopped.frames > 0, 'no frames recorded');
check(stopped.messages >= stopped.frames && stopped.bytes > 0, '%d frames in %d messages, %d bytes', ...
      stopped.frames, stopped.messages, stopped.bytes);
check(numel(stopped.path) >= numel(name) && strcmp(stopped.path(end - numel(name) + 1:end), name), ...
      'path %s does not end in %s', stopped.path, name);
check(stopped.startTime <= stopped.endTime, 'start time %g after end time %g', stopped.startTime, stopped.endTime);
near(stopped.endTime, 0.2, 1e-9, 'simulation time of the last frame');
listed = c.listRecordings();
row = listed(strcmp({listed.name}, name));
check(numel(row) == 1, 'listRecordings after stop: %d rows named %s', numel(row), name);
check(~row.active && strcmp(row.sceneId, sid) && row.frames == stopped.frames && row.bytes == stopped.bytes, ...
      'listRecordings after stop: active %d, scene ''%s'', %d frames, %d bytes; StopRecording said %s, %d, %d', ...
      row.active, row.sceneId, row.frames, row.bytes, sid, stopped.frames, stopped.bytes);

bytes = c.downloadRecording(name);
magic = uint8([137 77 67 65 80 48 13 10]);  % "\x89MCAP0\r\n", at both ends of a finished MCAP file
check(numel(bytes) == stopped.bytes, 'downloaded %d bytes of %d', numel(bytes), stopped.bytes);
check(numel(bytes) > 16 && isequal(bytes(1:8), magic) && isequal(bytes(end - 7:end), magic), ...
      'the download is not a finished MCAP file');

replay = c.replayRecording(name, 'octave replay');
cleanup = onCleanup(@() c.deleteScene(replay.sceneId));
check(~strcmp(replay.sceneId, sid) && replay.frames == stopped.frames && numel(replay.frameTimes) == replay.frames, ...
      'replay: %d frames, %d frame times, %d recorded', replay.frames, numel(replay.frameTimes), stopped.frames);
check(all(diff(replay.frameTimes) >= 0), 'frame times not in order');
near(replay.frameTimes(end), stopped.endTime, 0, 'last frame time');
[~, original] = c.getBodyPoses(sid, 'box');
[time, revision] = c.seekReplay(replay.sceneId, name, replay.frames - 1);
near(time, replay.frameTimes(end), 0, 'time after seeking the last frame');
check(revision > 0, 'revision %g after a seek', revision);
[~, seeked] = c.getBodyPoses(replay.sceneId, 'box');
near(seeked, original, 0, 'the box at the last frame');
[time, ~] = c.seekReplay(replay.sceneId, name, 0);
near(time, replay.frameTimes(1), 0, 'time after seeking the first frame');
[~, first] = c.getBodyPoses(replay.sceneId, 'box');
check(first(3) > original(3) + 0.1, 'the box at the first frame (z = %.4f m) is not above the last (%.4f m)', ...
      first(3), original(3));
end

function test_error_recording(c, sid)
expectError(@() c.stopRecording(sid), 'graspsim:NOT_FOUND', {sid, 'not being recorded'});
expectError(@() c.startRecording(sid, '../escape.mcap'), 'graspsim:INVALID_ARGUMENT', {'name', '../escape.mcap'});
expectError(@() c.startRecording(sid, 'x.mcap', 'Compression', 'brotli'), 'graspsim:INVALID_ARGUMENT', ...
            {'compression', 'brotli'});
expectError(@() c.startRecording('no-such-scene', 'x.mcap'), 'graspsim:NOT_FOUND', {'no-such-scene'});
name = sprintf('octave-errors-%s.mcap', regexprep(sid, '[^A-Za-z0-9_-]', '_'));
c.startRecording(sid, name, 'Groups', 'graspsim', 'Compression', 'lz4');
expectError(@() c.startRecording(sid, 'second.mcap'), 'graspsim:ALREADY_EXISTS', {sid});
stopped = c.stopRecording(sid);
check(strcmp(stopped.name, name) && isempty(stopped.ros2Path), 'a graspsim-only recording: %s, ros2 %s', ...
      stopped.name, stopped.ros2Path);
expectError(@() c.replayRecording('no-such-recording.mcap'), 'graspsim:NOT_FOUND', {'no-such-recording.mcap'});
expectError(@() c.seekReplay(sid, 'no-such-recording.mcap', 0), 'graspsim:NOT_FOUND', {'no-such-recording.mcap'});
expectError(@() c.seekReplay(sid, name, 0.5), 'graspsim:badArgument', {'frame'});
end

function test_error_other_services_unimplemented(c, sid)
% Every method is built now; these name what is wrong. PlanArmPath (docs/motion.md): without an arm, the field.
expectError(@() c.call('GraspService', 'PlanArmPath', struct('scene_id', sid)), 'graspsim:INVALID_ARGUMENT', {'arm_id'});
% SegmentScene (docs/perception.md): an empty cloud is named.
expectError(@() c.call('PerceptionService', 'SegmentScene', struct()), 'graspsim:INVALID_ARGUMENT', {'cloud.points'});
expectError(@() c.call('SceneService', 'NoSuchMethod', struct()), 'graspsim:NOT_FOUND', {'NoSuchMethod'});
expectError(@() c.call('SceneService', 'GetScene', struct('scene_idd', sid)), 'graspsim:INVALID_ARGUMENT', ...
            {'scene_idd'});
end

function test_error_client_side_arguments(c, sid)
expectError(@() c.setBodyPoses(sid, {'a', 'b'}, [0 0 0 1 0 0 0]), 'graspsim:badArgument', {'2-by-7'});
expectError(@() c.addObject(sid, 'x', 'Box', [1 1 1], 'Sphere', 1, 'Mass', 1), 'graspsim:badArgument', ...
            {'exactly one shape'});
expectError(@() c.addObject(sid, 'x', 'Box', [1 1], 'Mass', 1), 'graspsim:badArgument', {'box'});
expectError(@() c.addObject(sid, 'x', 'Sphere', 1, 'Colour', 'red'), 'graspsim:badArgument', {'colour'});
expectError(@() c.addObject(sid, 'x', 'Box', [1 1 1], 'Mass', 1, 'Inertia', [1 2 0; 0 1 0; 0 0 1]), ...
            'graspsim:badArgument', {'symmetric'});
expectError(@() c.addObject(sid, 'x', 'Vertices', zeros(3), 'Triangles', [0 1 2.5], 'Mass', 1, 'Inertia', eye(3)), ...
            'graspsim:badArgument', {'0-based'});
expectError(@() c.addRobot(sid, 'x'), 'graspsim:badArgument', {'builtin'});
expectError(@() c.uploadFile(sid, 'x', '/no/such/file.stl'), 'graspsim:badArgument', {'/no/such/file.stl'});
end

function test_error_unreachable_server(~, ~)
port = freePort();
closed = graspsim.Client(sprintf('127.0.0.1:%d', port), 'Timeout', 2);
expectError(@() closed.listScenes(), 'graspsim:UNAVAILABLE', {sprintf('%d', port)});
end

function test_demo_runs(c, ~)
before = c.listScenes();
output = evalc('graspsim_demo(c.Url)');
for fragment = {'built-in models:', 'schunk_pg70', 'bodies (5):', 'pg70/finger_right_joint  prismatic 0.0300 m', ...
                'mimics pg70/finger_left_joint', '14 rows x 6 cols', 'snapshot', 'cube_5cm           z = 0.7750 m', ...
                'after 1.500 s (1500 steps)', 'dropped_cube rests at z = 0.7750 m (table top + 25.0 mm)', 'asleep', ...
                'cell/pad_left  14 x 6 texels, ', 'cell/pad_right 14 x 6 texels, ', ...
                'heat map of cell/pad_left', 'stages approach > grasp > lift > hold > move_down > release > done', ...
                'peak sums', 'cube lifted 50.0 mm'}
  check(~isempty(strfind(output, fragment{1})), 'demo output lacks "%s":\n%s', fragment{1}, output);
end
after = c.listScenes();
check(numel(after) == numel(before), 'the demo left its scene behind');
end

% --- helpers ----------------------------------------------------------------------------------------------

function [gripper, cube] = buildCell(c, sid)
% The work cycle's cell (clients/python/examples/tactile_cycle.py): the table at the origin (top at 0.75 m), a
% 5 cm cube on it, the PG70 on its z axis ('schunk_pg70_on_z_axis') with its base at 1.05 m above the cube.
gripper = 'cell';
cube = 'cube';
c.addObject(sid, 'table', 'Builtin', 'table');
c.addObject(sid, cube, 'Builtin', 'cube_5cm', 'Pose', [0 0 0.775 1 0 0 0]);
c.addRobot(sid, gripper, 'Builtin', 'schunk_pg70_on_z_axis', 'BasePose', [0 0 1.05 1 0 0 0]);
end

function b = sceneBody(c, sid, id)
% One body of getScene by id.
scene = c.getScene(sid);
b = scene.bodies(strcmp({scene.bodies.id}, id));
check(numel(b) == 1, 'no body %s in the scene', id);
end

function [position, velocity, follower] = fingerState(c, sid)
% The PG70's finger_left_joint position (m) and velocity (m/s), and the mimic finger_right_joint's position.
scene = c.getScene(sid);
joints = scene.joints;
left = joints(strcmp({joints.id}, 'pg70/finger_left_joint'));
right = joints(strcmp({joints.id}, 'pg70/finger_right_joint'));
position = left.position;
velocity = left.velocity;
follower = right.position;
end

function check(condition, varargin)
if ~condition
  error('test:failed', varargin{:});
end
end

function near(actual, expected, tolerance, what)
check(isequal(size(actual), size(expected)), '%s: size %s, expected %s', what, mat2str(size(actual)), ...
      mat2str(size(expected)));
difference = max(abs(actual(:) - expected(:)));
check(isempty(difference) || difference <= tolerance, '%s: off by %g (tolerance %g): %s vs %s', what, difference, ...
      tolerance, mat2str(actual, 6), mat2str(expected, 6));
end

function err = expectError(action, identifier, fragments)
% action() raises identifier, and its message names every fragment (case-insensitive).
try
  action();
catch err
  check(strcmp(err.identifier, identifier), 'expected %s, got [%s] %s', identifier, err.identifier, err.message);
  for k = 1:numel(fragments)
    check(~isempty(strfind(lower(err.message), lower(fragments{k}))), 'message does not name "%s": %s', ...
          fragments{k}, err.message);
  end
  return;
end
error('test:failed', 'expected %s, but the call succeeded', identifier);
end

function names = methodNames(methods)
if iscell(methods)
  names = cellfun(@(m) m.name, methods, 'UniformOutput', false);
else
  names = {methods.name};
end
end

function [v, t] = boxMesh(edges)
% A closed box of full edge lengths edges centred on the origin: 8 vertices, 12 counter-clockwise triangles
% (0-based).
h = edges(:).' / 2;
v = [-1 -1 -1; 1 -1 -1; 1 1 -1; -1 1 -1; -1 -1 1; 1 -1 1; 1 1 1; -1 1 1] * diag(h);
t = [0 2 1; 0 3 2; 4 5 6; 4 6 7; 0 1 5; 0 5 4; 2 3 7; 2 7 6; 0 4 7; 0 7 3; 1 2 6; 1 6 5];
end

function [v, t] = prismMesh(r, l, n)
% A closed n-sided prism of radius r along z, length l, centred on the origin: centres of the bottom (index 0)
% and top (1) faces, then the bottom ring (2 ... n+1) and the top ring (n+2 ... 2n+1); 4n triangles
% counter-clockwise seen from outside.
angles = (0:n - 1).' * 2 * pi / n;
ring = [r * cos(angles), r * sin(angles)];
v = [0 0 -l / 2; 0 0 l / 2; ring, -l / 2 * ones(n, 1); ring, l / 2 * ones(n, 1)];
k = (0:n - 1).';
next = mod(k + 1, n);
bottom = 2 + k;
bottomNext = 2 + next;
top = 2 + n + k;
topNext = 2 + n + next;
t = [zeros(n, 1), bottomNext, bottom; ones(n, 1), top, topNext; bottom, bottomNext, topNext; bottom, topNext, top];
end

function bytes = stlBytes(v, t)
% A binary STL of a mesh (vertices N-by-3, 0-based triangles M-by-3).
n = size(t, 1);
bytes = [zeros(1, 80, 'uint8'), typecast(uint32(n), 'uint8')];
for k = 1:n
  corners = v(t(k, :) + 1, :);
  normal = cross(corners(2, :) - corners(1, :), corners(3, :) - corners(1, :));
  record = single([normal / norm(normal), reshape(corners.', 1, [])]);
  bytes = [bytes, typecast(record, 'uint8'), uint8([0 0])];  %#ok<AGROW>
end
end

function text = twoLinkUrdf(meshPath)
% base (a box) + arm on a revolute joint (limits [-1, 1] rad, axis z); the arm is the mesh at meshPath if given.
inertial = '<inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial>';
armShape = '<box size="0.05 0.05 0.2"/>';
if ~isempty(meshPath)
  armShape = sprintf('<mesh filename="%s"/>', meshPath);
end
link = @(name, shape) sprintf('<link name="%s">%s<collision><geometry>%s</geometry></collision></link>', ...
                              name, inertial, shape);
text = sprintf(['<?xml version="1.0"?>\n<robot name="arm">\n%s\n%s\n' ...
                '<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>' ...
                '<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/>' ...
                '</joint>\n</robot>\n'], link('base', '<box size="0.1 0.1 0.1"/>'), link('arm', armShape));
end

function q = quaternionAbout(axis, angle)
axis = axis / norm(axis);
q = [cos(angle / 2), sin(angle / 2) * axis];
end

function R = rotationMatrix(q)
q = q / norm(q);
w = q(1); x = q(2); y = q(3); z = q(4);
R = [1 - 2 * (y^2 + z^2), 2 * (x * y - w * z), 2 * (x * z + w * y);
     2 * (x * y + w * z), 1 - 2 * (x^2 + z^2), 2 * (y * z - w * x);
     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x^2 + y^2)];
end

function hex = sha256sum(bytes)
% SHA-256 computed outside the client: sha256sum(1) of a temporary file.
file = tempname();
fid = fopen(file, 'w');
fwrite(fid, bytes, 'uint8');
fclose(fid);
[status, out] = system(sprintf('sha256sum "%s"', file));
delete(file);
check(status == 0, 'sha256sum failed: %s', out);
hex = strtok(out);
end

function port = freePort()
% A TCP port nothing listens on (bound and released by python3).
[status, out] = system('python3 -c "import socket; s = socket.socket(); s.bind((''127.0.0.1'', 0)); print(s.getsockname()[1])"');
check(status == 0, 'python3 failed: %s', out);
port = str2double(strtrim(out));
end
