classdef Client < handle
  %CLIENT A connection to a graspsim server through its HTTP/JSON gateway (MATLAB and GNU Octave, pure .m).
  %
  %   c = graspsim.Client('http://127.0.0.1:8080')             % the server's --http-listen address
  %   c = graspsim.Client('http://127.0.0.1:8080', 'Timeout', 120)
  %   c = graspsim.Client('https://host:8080', 'Token', 'secret')  % a bearer token (docs/security.md)
  %
  %   Units are SI (m, kg, s, rad). A pose is 1-by-7 [x y z qw qx qy qz] (position in m, unit quaternion
  %   w, x, y, z); N poses are N-by-7. Ids are char rows; several ids are a cellstr (N-by-1 in results).
  %   64-bit counters (revision, sequence, sizes) come back as double.
  %
  %   Errors: a request the server refuses raises error('graspsim:<STATUS>', message) with the gRPC status
  %   name (graspsim:INVALID_ARGUMENT, graspsim:NOT_FOUND, graspsim:ALREADY_EXISTS, graspsim:FAILED_PRECONDITION,
  %   graspsim:RESOURCE_EXHAUSTED, graspsim:UNIMPLEMENTED, ...) and the server's message, which names the
  %   field and the bad value. graspsim:UNAVAILABLE means no server answered; graspsim:badArgument means the
  %   client refused the arguments before sending anything (wrong sizes, unknown options).
  %
  %   Scenes:      createScene, listScenes, getScene, deleteScene
  %   Files:       uploadFile, builtinModels
  %   Bodies:      addObject, addRobot, removeBody
  %   State:       setBodyPoses, getBodyPoses, setJointPositions, getJointPositions, watchScene
  %   Simulation:  stepSimulation, setSimulationParams, getSimulationParams, setActuator
  %   Sensors:     sampleSensor, tactileImage, streamSensors, runWorkCycle
  %   Grasps:      planGrasps
  %   Recordings:  startRecording, stopRecording, listRecordings, downloadRecording, replayRecording,
  %                seekReplay
  %   Anything:    call(service, method, request), listMethods
  %
  %   See also graspsim.Client/addObject, graspsim.Client/stepSimulation, graspsim.Client/call.

  properties (SetAccess = private)
    Url      % base URL of the gateway, e.g. 'http://127.0.0.1:8080'
  end
  properties
    Timeout = 60  % s: the deadline of each call (the server gets it too, as timeout_s)
  end
  properties (SetAccess = private, Hidden)
    Token = ''  % bearer token sent as "Authorization: Bearer <token>" with every call; '' = none
  end

  methods
    function obj = Client(url, varargin)
      %CLIENT c = graspsim.Client(url, 'Timeout', seconds, 'Token', token). url defaults to 'http://127.0.0.1:8080';
      %   'host:port' without a scheme means http. No request is sent until the first call.
      if nargin < 1 || isempty(url)
        url = 'http://127.0.0.1:8080';
      end
      if ~ischar(url)
        error('graspsim:badArgument', 'url must be a char row such as ''http://127.0.0.1:8080''');
      end
      if isempty(regexp(url, '^[A-Za-z][A-Za-z0-9+.-]*://', 'once'))
        url = ['http://' url];
      end
      while ~isempty(url) && url(end) == '/'
        url = url(1:end - 1);
      end
      options = graspsim.internal.parseOptions(struct('Timeout', 60, 'Token', ''), varargin, 'graspsim.Client');
      if ~ischar(options.Token)
        error('graspsim:badArgument', 'Token must be a char row (the bearer token)');
      end
      obj.Url = url;
      obj.Timeout = options.Timeout;
      obj.Token = options.Token;
    end

    function set.Timeout(obj, value)
      if ~isnumeric(value) || ~isscalar(value) || ~(value > 0) || ~isfinite(value)
        error('graspsim:badArgument', 'Timeout must be a positive finite number of seconds');
      end
      obj.Timeout = double(value);
    end

    % --- any method ---------------------------------------------------------------------------------------
    function response = call(obj, service, method, request, varargin)
      %CALL response = c.call(service, method, request): any method of the API, e.g.
      %   c.call('SceneService', 'GetScene', struct('scene_id', id)).
      %   request is a struct with the .proto's field names (or JSON text); absent fields are defaults.
      %   Vectors of numbers are arrays, a 1-by-1 number a scalar: wrap repeated fields in a cell
      %   ({'a'}, {struct(...)}) to send a one-element array. bytes fields are base64 text.
      %   A client-streaming method takes a cell array of request structs (one per stream message).
      %   The response is jsondecode's struct of the response message (snake_case fields, 64-bit integers
      %   as char, enums by name, bytes as base64). A server-streaming method returns an N-by-1 cell array of
      %   messages; end an endless stream (e.g. WatchScene) with 'MaxMessages', n (after n messages) and/or
      %   'MaxSeconds', t (after t s; the stream then ends normally, unlike at the client's Timeout).
      if nargin < 4 || isempty(request)
        request = struct();
      end
      options = graspsim.internal.parseOptions(struct('MaxMessages', [], 'MaxSeconds', []), varargin, 'call');
      query = '';
      if ~isempty(options.MaxMessages)
        query = sprintf('&max_messages=%d', round(options.MaxMessages));
      end
      if ~isempty(options.MaxSeconds)
        query = sprintf('%s&max_seconds=%.17g', query, options.MaxSeconds);
      end
      envelope = graspsim.internal.post(obj, service, method, request, query, obj.Timeout);
      graspsim.internal.raiseIfError(envelope);
      if isfield(envelope, 'responses')
        response = items(envelope.responses);
      else
        response = field(envelope, 'response', struct());
      end
    end

    function services = listMethods(obj)
      %LISTMETHODS The gateway's services and their methods (GET /v1), as jsondecode gives them.
      try
        text = webread([obj.Url '/v1'], weboptions('Timeout', obj.Timeout, 'ContentType', 'text'));
      catch err
        error('graspsim:UNAVAILABLE', 'no answer from the graspsim HTTP gateway at %s: %s', obj.Url, err.message);
      end
      services = jsondecode(char(text(:).'));
    end

    % --- scenes -------------------------------------------------------------------------------------------
    function summary = createScene(obj, name)
      %CREATESCENE summary = c.createScene(name): a new empty scene. summary.id is the server's scene id;
      %   also name, bodyCount, robotCount, revision, time (s).
      if nargin < 2
        name = 'scene';
      end
      scene = obj.sceneCall('CreateScene', struct('name', name));
      summary = graspsim.internal.decode('SceneSummary', field(scene, 'summary', struct()));
    end

    function summaries = listScenes(obj)
      %LISTSCENES N-by-1 struct array of the summaries of every scene (id, name, bodyCount, robotCount,
      %   revision, time).
      response = obj.sceneCall('ListScenes', struct());
      summaries = graspsim.internal.decode('SceneSummary', field(response, 'scenes', []));
    end

    function scene = getScene(obj, sceneId, varargin)
      %GETSCENE scene = c.getScene(sceneId, 'IncludeGeometry', false): the whole scene, a struct with
      %   summary, bodies, joints, robots, tactileArrays, files (struct arrays, N-by-1).
      %   Body: id, robotId, motion ('static'|'free'|'articulated'), pose 1-by-7, velocity 1-by-6
      %     [vx vy vz wx wy wz] (m/s of the centre of mass, rad/s, world frame; zero unless free), sleeping
      %     (a free body at rest that the simulation skips), mass, centerOfMass, inertia 3-by-3, friction
      %     [static dynamic], contact (stiffness, damping, bristleStiffness, bristleDamping, viscousFriction,
      %     stribeckVelocity; 0 = the scene's default), triangleCount, collision (shapes: type, size,
      %     vertices, triangles, meshFile, origin, scale).
      %   With IncludeGeometry true, inline meshes come with vertices N-by-3 double (m; exactly the float32
      %   values the server holds) and triangles M-by-3 double of 0-BASED vertex indices (add 1 for patch or
      %   trisurf).
      %   Joint: id, robotId, type, parentBody, childBody, origin, axis, lower, upper, velocityLimit,
      %     effortLimit, position, velocity (rad/s or m/s), mimic (jointId, multiplier, offset).
      %     Robot: id, source, baseBody, bodyIds, jointIds, tactileArrayIds. Tactile array: id, bodyId, origin,
      %     rows, cols, pitch, thickness, subdivision, elements, bendRadius. File: path, size, sha256.
      options = graspsim.internal.parseOptions(struct('IncludeGeometry', false), varargin, 'getScene');
      response = obj.sceneCall('GetScene', ...
                       struct('scene_id', sceneId, 'include_geometry', logical(options.IncludeGeometry)));
      scene = struct('summary', graspsim.internal.decode('SceneSummary', field(response, 'summary', struct())), ...
                     'bodies', graspsim.internal.decode('Body', field(response, 'bodies', [])), ...
                     'joints', graspsim.internal.decode('Joint', field(response, 'joints', [])), ...
                     'robots', graspsim.internal.decode('Robot', field(response, 'robots', [])), ...
                     'tactileArrays', graspsim.internal.decode('TactileArray', ...
                                                               field(response, 'tactile_arrays', [])), ...
                     'files', graspsim.internal.decode('FileInfo', field(response, 'files', [])));
    end

    function deleteScene(obj, sceneId)
      %DELETESCENE c.deleteScene(sceneId): deletes a scene with everything in it.
      obj.sceneCall('DeleteScene', struct('scene_id', sceneId));
    end

    % --- files and models ---------------------------------------------------------------------------------
    function info = uploadFile(obj, sceneId, path, data, varargin)
      %UPLOADFILE info = c.uploadFile(sceneId, path, data, 'ChunkSize', 1048576): stores a file in a scene.
      %   path is how a URDF or 'MeshFile' names it (e.g. 'meshes/finger.stl'); data is the content
      %   (uint8 vector) or the name of a local file (char). The file travels in chunks of ChunkSize bytes
      %   with its size and SHA-256, which the server checks. Returns info.path, info.size, info.sha256.
      options = graspsim.internal.parseOptions(struct('ChunkSize', 1048576), varargin, 'uploadFile');
      bytes = graspsim.internal.readBytes(data, 'uploadFile data');
      chunk = round(double(options.ChunkSize));
      if ~(chunk > 0)
        error('graspsim:badArgument', 'ChunkSize must be > 0 bytes');
      end
      header = struct('scene_id', sceneId, 'path', path, 'total_size', numel(bytes), ...
                      'sha256', graspsim.internal.sha256hex(bytes));
      starts = 1:chunk:max(numel(bytes), 1);
      messages = cell(1, numel(starts));
      for k = 1:numel(starts)
        piece = bytes(starts(k):min(starts(k) + chunk - 1, numel(bytes)));
        messages{k} = struct('data', graspsim.internal.encodeBytes(piece));
      end
      messages{1}.header = header;
      info = graspsim.internal.decode('FileInfo', obj.sceneCall('UploadFile', messages));
    end

    function models = builtinModels(obj)
      %BUILTINMODELS N-by-1 struct array of the server's built-in models: name, kind ('robot' for addRobot,
      %   'object' for addObject), description.
      response = obj.sceneCall('ListBuiltinModels', struct());
      models = graspsim.internal.decode('BuiltinModel', field(response, 'models', []));
    end

    % --- bodies and robots --------------------------------------------------------------------------------
    function body = addObject(obj, sceneId, name, varargin)
      %ADDOBJECT body = c.addObject(sceneId, name, shape, value, ...): adds a rigid object; returns the body
      %   as the server holds it (see getScene). Give exactly one shape:
      %     'Builtin', 'cube_5cm'        a built-in object (its own mass and friction unless given)
      %     'Box', [x y z]               full edge lengths, m
      %     'Sphere', r                  m
      %     'Cylinder', [r l]            along z, m
      %     'Vertices', V, 'Triangles', T   inline mesh: V N-by-3 (m, sent as float32), T M-by-3 of 0-BASED
      %                                  vertex indices, counter-clockwise seen from outside
      %     'MeshFile', 'meshes/x.stl'   a file uploaded with uploadFile
      %   Options:
      %     'Mass', kg                   required with a shape (not with 'Builtin')
      %     'Inertia', 3-by-3            kg m^2 about the centre of mass, symmetric. With a Mass but no Inertia
      %                                  it is computed for uniform density: box m(b^2+c^2)/12 ..., sphere
      %                                  2/5 m r^2, cylinder m r^2/2 about z and m(3r^2+l^2)/12 about x, y,
      %                                  closed mesh by the divergence theorem (its centroid becomes the
      %                                  centre of mass unless given). MeshFile and Builtin need Inertia.
      %     'CenterOfMass', [x y z]      m, body frame
      %     'Friction', [static dynamic] coefficients (default: the server's 0.6, 0.4 or the model's own)
      %     'Pose', [x y z qw qx qy qz]  body frame in the world
      %     'Static', true               a fixed body (a table); it needs no Mass
      %     'InertiaSource', 'auto'      without a Mass, a moving shape takes the solid's mass properties at
      %                                  'Density' kg/m^3 (default 1000; reported in body.warnings);
      %                                  'from_file' or 'Strict', true require the Mass
      defaults = struct('Builtin', [], 'Box', [], 'Sphere', [], 'Cylinder', [], 'Vertices', [], 'Triangles', [], ...
                        'MeshFile', [], 'Mass', [], 'Inertia', [], 'CenterOfMass', [], 'Friction', [], ...
                        'Pose', [], 'Static', false, 'InertiaSource', 'auto', 'Density', [], 'Strict', false);
      o = graspsim.internal.parseOptions(defaults, varargin, 'addObject');
      [kind, value] = pickShape(o);
      request = struct('scene_id', sceneId, 'name', name);
      switch kind
        case 'builtin'
          request.builtin = value;
        case 'box'
          request.geometry = struct('box', struct('size', graspsim.internal.toVec3(value, 'Box')));
        case 'sphere'
          request.geometry = struct('sphere', struct('radius', value));
        case 'cylinder'
          request.geometry = struct('cylinder', struct('radius', value(1), 'length', value(2)));
        case 'mesh'
          request.geometry = struct('mesh', graspsim.internal.packMesh(value{1}, value{2}));
        case 'meshFile'
          request.geometry = struct('mesh_file', value);
      end
      inertial = makeInertial(kind, value, o.Mass, o.Inertia, o.CenterOfMass);
      if ~isempty(inertial)
        request.inertial = inertial;
      end
      if ~isempty(o.Friction)
        if numel(o.Friction) ~= 2
          error('graspsim:badArgument', 'Friction needs 2 values [static dynamic], got %d', numel(o.Friction));
        end
        request.material = struct('static_friction', o.Friction(1), 'dynamic_friction', o.Friction(2));
      end
      if ~isempty(o.Pose)
        request.pose = graspsim.internal.toPose(o.Pose, 'Pose');
      end
      request.is_static = logical(o.Static);
      request.import_options = importOptions(o.InertiaSource, o.Density, o.Strict, '', 'addObject');
      response = obj.sceneCall('AddObject', request);
      body = graspsim.internal.decode('Body', response);
      body.warnings = importWarnings(field(response, 'warnings', []));
    end

    function robot = addRobot(obj, sceneId, name, varargin)
      %ADDROBOT added = c.addRobot(sceneId, name, 'Builtin', 'schunk_pg70' | 'Urdf', text | 'Mjcf', text |
      %   'Sdf', text | 'Path', file, ...): adds a robot whose root link sits at 'BasePose' [x y z qw qx qy qz]
      %   (world; default the origin).
      %   'Path', 'robot.urdf' (or .xml MJCF, .sdf) reads a local file and uploads every mesh its collision
      %   geometry names that the scene does not already hold with the same SHA-256, then adds it: one call.
      %   package://pkg/... resolves under 'PackageRoots': a struct or containers.Map {pkg: folder}, or a
      %   cellstr of folders holding package folders ([] = the file's folder and its parents); relative paths
      %   against the file's folder. Files missing on disk: one graspsim:missingFiles error naming them all,
      %   before anything is sent. (MJCF <include> is not followed here; the Python client follows it.)
      %   'Files', struct('path', {...}, 'data', {...}) sends small mesh files with the request (data uint8
      %   or a local file name); bigger ones go through uploadFile first.
      %   'Inertia', 'auto' | 'from_file' | 'from_geometry' (default 'auto': the file's where physical, else from
      %   the collision geometry at 'Density' kg/m^3, default 1000); 'Strict', true refuses anything that needs
      %   a repair; 'ModelName' picks a model of an SDF <world>.
      %   Returns a struct: robot (id, source, baseBody, bodyIds, jointIds, tactileArrayIds), bodies,
      %   joints, tactileArrays (as in getScene), warnings (struct array: element, value, action; every
      %   repair made to the file). Body ids are '<name>/<link>', joint ids '<name>/<joint>'.
      defaults = struct('Builtin', [], 'Urdf', [], 'Mjcf', [], 'Sdf', [], 'Path', [], 'PackageRoots', [], ...
                        'BasePose', [], 'Files', [], 'Inertia', 'auto', 'Density', [], 'Strict', false, ...
                        'ModelName', '');
      o = graspsim.internal.parseOptions(defaults, varargin, 'addRobot');
      sources = {'Builtin', 'Urdf', 'Mjcf', 'Sdf', 'Path'};
      given = sources(cellfun(@(s) ~isempty(o.(s)), sources));
      if numel(given) ~= 1
        error('graspsim:badArgument', 'addRobot: give exactly one of ''Builtin'', ''Urdf'', ''Mjcf'', ''Sdf'', ''Path''');
      end
      request = struct('scene_id', sceneId, 'name', name);
      switch given{1}
        case 'Builtin'
          request.builtin = o.Builtin;
        case 'Path'
          [format, text, scenePaths, localPaths] = graspsim.internal.robotFiles(o.Path, o.PackageRoots);
          obj.uploadMissing(sceneId, scenePaths, localPaths);
          request.(format) = text;
        otherwise
          request.(lower(given{1})) = o.(given{1});
      end
      request.import_options = importOptions(o.Inertia, o.Density, o.Strict, o.ModelName, 'addRobot');
      if ~isempty(o.BasePose)
        request.base_pose = graspsim.internal.toPose(o.BasePose, 'BasePose');
      end
      if ~isempty(o.Files)
        if ~isstruct(o.Files) || ~isfield(o.Files, 'path') || ~isfield(o.Files, 'data')
          error('graspsim:badArgument', 'Files must be a struct array with fields path and data');
        end
        files = cell(1, numel(o.Files));
        for k = 1:numel(o.Files)
          bytes = graspsim.internal.readBytes(o.Files(k).data, sprintf('Files(%d).data', k));
          files{k} = struct('path', o.Files(k).path, 'data', graspsim.internal.encodeBytes(bytes));
        end
        request.files = files;
      end
      response = obj.sceneCall('AddRobot', request);
      robot = struct('robot', graspsim.internal.decode('Robot', field(response, 'robot', struct())), ...
                     'bodies', graspsim.internal.decode('Body', field(response, 'bodies', [])), ...
                     'joints', graspsim.internal.decode('Joint', field(response, 'joints', [])), ...
                     'tactileArrays', graspsim.internal.decode('TactileArray', field(response, 'tactile_arrays', [])), ...
                     'warnings', importWarnings(field(response, 'warnings', [])));
    end

    function uploaded = uploadMissing(obj, sceneId, scenePaths, localPaths)
      %UPLOADMISSING uploaded = c.uploadMissing(sceneId, scenePaths, localPaths): uploads each local file
      %   localPaths{k} as scenePaths{k} unless the scene holds that path with the same SHA-256 already;
      %   returns the uploaded scene paths (cellstr).
      uploaded = {};
      if isempty(scenePaths)
        return
      end
      files = obj.getScene(sceneId).files;
      for k = 1:numel(scenePaths)
        bytes = graspsim.internal.readBytes(localPaths{k}, 'addRobot Path');
        held = [];
        if ~isempty(files)
          held = files(strcmp({files.path}, scenePaths{k}));
        end
        if ~isempty(held) && strcmp(held(1).sha256, graspsim.internal.sha256hex(bytes))
          continue
        end
        obj.uploadFile(sceneId, scenePaths{k}, bytes);
        uploaded{end + 1} = scenePaths{k}; %#ok<AGROW>
      end
    end

    function removed = removeBody(obj, sceneId, id)
      %REMOVEBODY removed = c.removeBody(sceneId, id): removes an object, or a robot (by robot id) with its
      %   links, joints and sensors. Returns the removed body ids (N-by-1 cellstr).
      response = obj.sceneCall('RemoveBody', struct('scene_id', sceneId, 'id', id));
      removed = stringList(field(response, 'removed_body_ids', []));
    end

    % --- poses and joints ---------------------------------------------------------------------------------
    function revision = setBodyPoses(obj, sceneId, ids, poses)
      %SETBODYPOSES revision = c.setBodyPoses(sceneId, ids, poses): world poses by body id (an object, a
      %   robot id or a robot's base body); ids a char or an N-cellstr, poses N-by-7. All or none apply.
      ids = idList(ids, 'ids');
      if size(poses, 2) ~= 7 && numel(poses) == 7
        poses = reshape(poses, 1, 7);
      end
      if size(poses, 2) ~= 7 || size(poses, 1) ~= numel(ids)
        error('graspsim:badArgument', 'poses must be %d-by-7 (one row [x y z qw qx qy qz] per id), got %s', ...
              numel(ids), mat2str(size(poses)));
      end
      entries = cell(1, numel(ids));
      for k = 1:numel(ids)
        pose = graspsim.internal.toPose(poses(k, :), sprintf('poses(%d,:)', k));
        entries{k} = struct('body_id', ids{k}, 'pose', pose);
      end
      response = obj.sceneCall('SetBodyPoses', struct('scene_id', sceneId, 'poses', {entries}));
      revision = number(field(response, 'revision', 0));
    end

    function [ids, poses, revision, time] = getBodyPoses(obj, sceneId, ids)
      %GETBODYPOSES [ids, poses, revision, time] = c.getBodyPoses(sceneId, ids): world poses (N-by-7
      %   [x y z qw qx qy qz]) of the given bodies, in the order of the returned ids (N-by-1 cellstr).
      %   ids omitted or {} = every body.
      if nargin < 3
        ids = {};
      end
      request = struct('scene_id', sceneId, 'body_ids', {idList(ids, 'ids')});
      response = obj.sceneCall('GetBodyPoses', request);
      list = graspsim.internal.decode('BodyPose', field(response, 'poses', []));
      ids = {list.bodyId}.';
      poses = reshape([list.pose], 7, []).';
      revision = number(field(response, 'revision', 0));
      time = number(field(response, 'time', 0));
    end

    function revision = setJointPositions(obj, sceneId, ids, values)
      %SETJOINTPOSITIONS revision = c.setJointPositions(sceneId, ids, values): joint positions (rad or m)
      %   by joint id ('<robot>/<joint>'); ids a char or an N-cellstr, values N numbers. All or none apply;
      %   mimic joints follow their leader.
      ids = idList(ids, 'ids');
      if numel(values) ~= numel(ids) || ~isnumeric(values)
        error('graspsim:badArgument', 'values must hold %d numbers (one per id), got %d', numel(ids), numel(values));
      end
      entries = cell(1, numel(ids));
      for k = 1:numel(ids)
        entries{k} = struct('joint_id', ids{k}, 'position', double(values(k)));
      end
      response = obj.sceneCall('SetJointPositions', struct('scene_id', sceneId, 'positions', {entries}));
      revision = number(field(response, 'revision', 0));
    end

    function [ids, values, revision] = getJointPositions(obj, sceneId, ids)
      %GETJOINTPOSITIONS [ids, values, revision] = c.getJointPositions(sceneId, ids): positions (N-by-1,
      %   rad or m) in the order of the returned ids (N-by-1 cellstr). ids omitted or {} = every joint.
      if nargin < 3
        ids = {};
      end
      request = struct('scene_id', sceneId, 'joint_ids', {idList(ids, 'ids')});
      response = obj.sceneCall('GetJointPositions', request);
      list = graspsim.internal.decode('JointPosition', field(response, 'positions', []));
      ids = {list.jointId}.';
      values = reshape([list.position], [], 1);
      revision = number(field(response, 'revision', 0));
    end

    % --- streams and simulation ---------------------------------------------------------------------------
    function snapshots = watchScene(obj, sceneId, n, varargin)
      %WATCHSCENE snapshots = c.watchScene(sceneId, n, 'MaxRateHz', 0, 'Timeout', c.Timeout): the next n
      %   snapshots of the scene (the first comes at once, then one per change, at most MaxRateHz; 0 = the
      %   server's default). Returns when n arrived, or after Timeout s with those that arrived by then.
      %   n-by-1 struct array: sequence, revision, time (s), bodyIds, poses (N-by-7 [x y z qw qx qy qz]),
      %   jointIds, jointPositions (J-by-1, rad or m).
      if nargin < 3 || isempty(n)
        n = 1;
      end
      o = graspsim.internal.parseOptions(struct('MaxRateHz', 0, 'Timeout', obj.Timeout), varargin, 'watchScene');
      if ~(n >= 1) || n ~= round(n)
        error('graspsim:badArgument', 'n must be a whole number of snapshots >= 1');
      end
      request = struct('scene_id', sceneId, 'max_rate_hz', double(o.MaxRateHz));
      % max_seconds ends the stream normally (OK) when fewer than n snapshots came in time.
      query = sprintf('&max_messages=%d&max_seconds=%.17g', n, o.Timeout);
      envelope = graspsim.internal.post(obj, 'SceneService', 'WatchScene', request, query, o.Timeout);
      graspsim.internal.raiseIfError(envelope);
      snapshots = graspsim.internal.decode('SceneSnapshot', field(envelope, 'responses', []));
    end

    function result = stepSimulation(obj, sceneId, varargin)
      %STEPSIMULATION result = c.stepSimulation(sceneId, 'Duration', s | 'Steps', n | 'UntilTime', t):
      %   advances the dynamic simulation by a duration (s, rounded to whole steps of the time step), a number
      %   of steps, or until the simulation time t (s). c.stepSimulation(sceneId, s) is 'Duration', s.
      %   Returns a struct: time (s, the simulation time after the steps), steps (taken by this call),
      %   contacts (contact points in the last step), awakeBodies (free bodies integrated in the last step),
      %   revision. watchScene streams see the motion. A diverging run raises graspsim:FAILED_PRECONDITION
      %   naming the body, step and quantity, and leaves the scene at its last finite state.
      if numel(varargin) == 1 && isnumeric(varargin{1})
        varargin = {'Duration', varargin{1}};
      end
      o = graspsim.internal.parseOptions(struct('Duration', [], 'Steps', [], 'UntilTime', []), varargin, ...
                                         'stepSimulation');
      given = {'Duration', 'Steps', 'UntilTime'};
      given = given(~cellfun(@isempty, {o.Duration, o.Steps, o.UntilTime}));
      if numel(given) ~= 1
        error('graspsim:badArgument', ...
              'stepSimulation: give exactly one of ''Duration'' (s), ''Steps'', ''UntilTime'' (s), got %d', ...
              numel(given));
      end
      value = o.(given{1});
      if ~isnumeric(value) || ~isscalar(value) || ~isreal(value)
        error('graspsim:badArgument', 'stepSimulation: %s must be one real number', given{1});
      end
      request = struct('scene_id', sceneId);
      switch given{1}
        case 'Duration'
          request.duration = double(value);
        case 'UntilTime'
          request.until_time = double(value);
        case 'Steps'
          if ~(value >= 0 && value <= 4294967295 && value == round(value))
            error('graspsim:badArgument', 'stepSimulation: Steps must be a whole number from 0 to 2^32-1, got %g', ...
                  double(value));
          end
          request.steps = double(value);
      end
      result = graspsim.internal.decode('StepSimulationResponse', obj.sceneCall('StepSimulation', request));
    end

    function params = setSimulationParams(obj, sceneId, varargin)
      %SETSIMULATIONPARAMS params = c.setSimulationParams(sceneId, name, value, ...) or
      %   c.setSimulationParams(sceneId, paramsStruct): sets the scene's simulation parameters and returns
      %   them as the server now holds them (as getSimulationParams). Like the Python client, a call sets
      %   the whole set: a parameter not given (or [], or 0) takes the server's DEFAULT, not its current
      %   value, so change one parameter with p = c.getSimulationParams(id); p.timeStep = 5e-4;
      %   c.setSimulationParams(id, p). Names are case-insensitive (TimeStep, timeStep, time_step):
      %     'TimeStep', s              the step of stepSimulation
      %     'Substeps', n              integration steps per step
      %     'Integrator', name         'linearly_implicit_euler' (default; stiff contacts stable at
      %                                millisecond steps), 'semi_implicit_euler', 'velocity_verlet',
      %                                'runge_kutta_4'
      %     'Gravity', [x y z]         m/s^2 (default [0 0 -9.81]; [0 0 0] is no gravity)
      %     'Contact', struct(...)     default contact parameters of every body: stiffness (N/m per contact
      %                                point), damping (N s/m), bristleStiffness, bristleDamping (LuGre sigma0
      %                                N/m, sigma1 N s/m), viscousFriction (N s/m), stribeckVelocity (m/s)
      %     'SampleSpacing', m         spacing of the surface samples of primitives
      %     'SleepSpeed', m/s          speed (and rad/s) below which a free body is at rest
      %     'SleepTime', s             time at rest before a body sleeps
      %   A bad value raises graspsim:INVALID_ARGUMENT naming the field (e.g. params.time_step) and changes
      %   nothing.
      if numel(varargin) == 1 && isstruct(varargin{1}) && isscalar(varargin{1})
        given = varargin{1};
        names = fieldnames(given);
        varargin = cell(1, 2 * numel(names));
        varargin(1:2:end) = names;
        varargin(2:2:end) = struct2cell(given);
      end
      if mod(numel(varargin), 2) ~= 0
        error('graspsim:badArgument', 'setSimulationParams: give name-value pairs or one struct of parameters');
      end
      known = {'TimeStep', 'time_step'; 'Substeps', 'substeps'; 'Integrator', 'integrator'; ...
               'Gravity', 'gravity'; 'Contact', 'contact'; 'SampleSpacing', 'sample_spacing'; ...
               'SleepSpeed', 'sleep_speed'; 'SleepTime', 'sleep_time'};
      message = struct();
      for k = 1:2:numel(varargin)
        row = matchName(varargin{k}, known(:, 1), 'setSimulationParams');
        name = known{row, 1};
        value = varargin{k + 1};
        if isempty(value)
          continue;  % not given: the server's default
        end
        switch name
          case 'Integrator'
            message.integrator = integratorName(value);
          case 'Gravity'
            message.gravity = graspsim.internal.toVec3(value, 'Gravity');
          case 'Contact'
            message.contact = contactMessage(value, 'Contact');
          otherwise
            if ~isnumeric(value) || ~isscalar(value) || ~isreal(value)
              error('graspsim:badArgument', 'setSimulationParams: %s must be one real number', name);
            end
            if strcmp(name, 'Substeps') && ~(value >= 0 && value <= 4294967295 && value == round(value))
              error('graspsim:badArgument', 'setSimulationParams: Substeps must be a whole number >= 0, got %g', ...
                    double(value));
            end
            message.(known{row, 2}) = double(value);
        end
      end
      response = obj.sceneCall('SetSimulationParams', struct('scene_id', sceneId, 'params', message));
      params = graspsim.internal.decode('SimulationParams', response);
    end

    function params = getSimulationParams(obj, sceneId)
      %GETSIMULATIONPARAMS params = c.getSimulationParams(sceneId): the scene's simulation parameters with
      %   the server's defaults filled in: timeStep (s), substeps, integrator ('linearly_implicit_euler',
      %   'semi_implicit_euler', 'velocity_verlet', 'runge_kutta_4'), gravity 1-by-3 (m/s^2), contact (stiffness, damping,
      %   bristleStiffness, bristleDamping, viscousFriction, stribeckVelocity), sampleSpacing (m), sleepSpeed
      %   (m/s), sleepTime (s). setSimulationParams takes this struct back.
      response = obj.sceneCall('GetSimulationParams', struct('scene_id', sceneId));
      params = graspsim.internal.decode('SimulationParams', response);
    end

    function setActuator(obj, sceneId, jointId, mode, value, currentLimit)
      %SETACTUATOR c.setActuator(sceneId, jointId, mode, value, currentLimit): drives a joint with its DC
      %   motor from the next stepSimulation on. mode 'velocity' (value m/s or rad/s), 'position' (m or
      %   rad), 'voltage' (V) or 'off' (no drive). currentLimit (A) caps the motor current, i.e. the force;
      %   0 or omitted = the motor's own. jointId is an independent joint (not a mimic follower): the built-in
      %   PG70's 'pg70/finger_left_joint' uses the PG70 drive and moves both fingers, other joints a generic
      %   24 V motor. Other motors: c.call('SceneService', 'SetActuators', ...) with an ActuatorCommand.motor.
      if nargin < 5 || isempty(value)
        value = 0;
      end
      if nargin < 6 || isempty(currentLimit)
        currentLimit = 0;
      end
      modes = {'off', 'voltage', 'velocity', 'position'};
      if ~ischar(mode) || ~any(strcmpi(mode, modes))
        error('graspsim:badArgument', 'setActuator: mode must be one of %s', strjoin(modes, ', '));
      end
      if ~ischar(jointId)
        error('graspsim:badArgument', 'setActuator: jointId must be a char row such as ''pg70/finger_left_joint''');
      end
      if ~isnumeric(value) || ~isscalar(value) || ~isnumeric(currentLimit) || ~isscalar(currentLimit)
        error('graspsim:badArgument', 'setActuator: value and currentLimit must be single numbers');
      end
      command = struct('joint_id', jointId, 'mode', ['ACTUATOR_MODE_' upper(mode)], 'value', double(value), ...
                       'current_limit', double(currentLimit));
      obj.sceneCall('SetActuators', struct('scene_id', sceneId, 'commands', {{command}}));
    end

    % --- sensors (TactileService) -------------------------------------------------------------------------
    function reading = sampleSensor(obj, sceneId, sensorId)
      %SAMPLESENSOR reading = c.sampleSensor(sceneId, sensorId): one reading of a sensor in the scene's
      %   current state. sensorId is a tactile array ('pg70/pad_left', 'pg70/pad_right'), a robot's gripper
      %   sensor ('pg70/gripper') or a joint, whose 6-axis force/torque sensor it reads
      %   ('pg70/finger_left_joint'). A struct: sensorId, kind ('tactile' | 'gripper' | 'forceTorque'), time
      %   (s, simulation time of the state read), and the fields of its kind (the other kinds' fields are []):
      %     tactile: rows, cols (texels; rows along the pad's y, cols along its x), intensities rows-by-cols
      %       double (0..4095, 12 bit, proportional to the texel's normal force, saturated), forces
      %       rows-by-cols-by-3 double (N, the force the object exerts on each texel in the pad frame, whose
      %       z is the pad's normal: forces(r, c, :) = [x y z]), intensitySum, forceSum 1-by-3 (N, pad frame).
      %     gripper: fingerDistance (m, the sum of the finger joints' positions; 0 = closed), motorCurrent
      %       (A, of the driven finger's motor; 0 when undriven), fingerVelocity (m/s; negative = closing).
      %     forceTorque: force 1-by-3 (N) and torque 1-by-3 (N m, about the frame's origin) that the joint
      %       transmits to its child body (and all it carries), in the child body's frame.
      %   An unknown id raises graspsim:NOT_FOUND listing the scene's sensors.
      response = graspsim.internal.unary(obj, 'TactileService', 'Sample', ...
                                         struct('scene_id', sceneId, 'sensor_id', sensorId));
      reading = graspsim.internal.decode('SensorReading', response);
    end

    function [png, width, height] = tactileImage(obj, sceneId, sensorId, scale)
      %TACTILEIMAGE [png, width, height] = c.tactileImage(sceneId, sensorId, scale): a tactile array's
      %   current reading as a PNG heat map (inferno colour map, black = no pressure), scale pixels per texel
      %   (omitted or 0 = 20; at most 4096 px a side). png is a 1-by-N uint8 row of the PNG file's bytes;
      %   width and height in pixels (a PG70 pad, 14 rows x 6 cols, at scale 20 is 120 x 280 px).
      %   Write it to a file and read it back as an image:
      %     fid = fopen('pad.png', 'w'); fwrite(fid, png, 'uint8'); fclose(fid);
      %     img = imread('pad.png');   % height-by-width-by-3 uint8
      if nargin < 4 || isempty(scale)
        scale = 0;
      end
      if ~isnumeric(scale) || ~isscalar(scale) || ~(scale >= 0 && scale <= 4294967295) || scale ~= round(scale)
        error('graspsim:badArgument', 'tactileImage: scale must be a whole number of pixels per texel >= 0');
      end
      response = graspsim.internal.unary(obj, 'TactileService', 'GetTactileImage', ...
                                         struct('scene_id', sceneId, 'sensor_id', sensorId, 'scale', double(scale)));
      png = graspsim.internal.decodeBytes(field(response, 'png', ''));
      width = number(field(response, 'width', 0));
      height = number(field(response, 'height', 0));
    end

    function readings = streamSensors(obj, sceneId, sensorIds, rateHz, varargin)
      %STREAMSENSORS readings = c.streamSensors(sceneId, sensorIds, rateHz, 'MaxMessages', n,
      %   'MaxSeconds', t): readings from TactileService.Stream, one per sensor id in each round: the first
      %   round at once, then one whenever the scene changes, at most rateHz rounds per second (> 0; the
      %   server caps it), always of the newest state. sensorIds a char or a cellstr. The stream ends after
      %   n readings (default one round, numel(sensorIds)) or after t s (default the client's Timeout) with
      %   those that arrived by then. readings is an n-by-1 struct array as sampleSensor gives (sensorId,
      %   kind, time, ... ; the fields of the other kinds are []).
      ids = idList(sensorIds, 'sensorIds');
      if nargin < 4 || ~isnumeric(rateHz) || ~isscalar(rateHz) || ~isreal(rateHz)
        error('graspsim:badArgument', 'streamSensors: give rateHz, one number of rounds per second (> 0)');
      end
      o = graspsim.internal.parseOptions(struct('MaxMessages', max(numel(ids), 1), 'MaxSeconds', obj.Timeout), ...
                                         varargin, 'streamSensors');
      n = o.MaxMessages;
      if ~isnumeric(n) || ~isscalar(n) || ~(n >= 1) || n ~= round(n)
        error('graspsim:badArgument', 'streamSensors: MaxMessages must be a whole number of readings >= 1');
      end
      if ~isnumeric(o.MaxSeconds) || ~isscalar(o.MaxSeconds) || ~(o.MaxSeconds > 0) || ~isfinite(o.MaxSeconds)
        error('graspsim:badArgument', 'streamSensors: MaxSeconds must be a positive finite number of seconds');
      end
      request = struct('scene_id', sceneId, 'sensor_ids', {ids}, 'rate_hz', double(rateHz));
      % max_seconds ends the stream normally (OK) when fewer than n readings came in time.
      query = sprintf('&max_messages=%d&max_seconds=%.17g', n, o.MaxSeconds);
      envelope = graspsim.internal.post(obj, 'TactileService', 'Stream', request, query, ...
                                        max(obj.Timeout, o.MaxSeconds));
      graspsim.internal.raiseIfError(envelope);
      readings = graspsim.internal.decode('SensorReading', field(envelope, 'responses', []));
    end

    function result = runWorkCycle(obj, sceneId, gripperId, objectId, varargin)
      %RUNWORKCYCLE result = c.runWorkCycle(sceneId, gripperId, objectId, name, value, ...): runs the grasp
      %   work cycle on a gripper carried by a vertical axis (the built-in robot 'schunk_pg70_on_z_axis':
      %   joint '<gripper>/z_axis' lowers and lifts the PG70) picking objectId (resting below it):
      %   approach, grasp (velocity control until the first tactile contact, then force control of the
      %   tactile sum), lift, hold, move_down, release, done. The simulation runs on the server; the call
      %   returns when the cycle is done. Options (0 = the server's default):
      %     'TactileSetpoint', s   intensity sum per pad the force controller holds (default 60000; at low
      %                            coverage the pads cannot reach it: 30000 works at every coverage)
      %     'LiftHeight', m        default 0.05
      %     'Coverage', f          fraction (0, 1] of the pads' length the object covers (default 1)
      %     'FrameRateHz', r       progress frames per simulated second, plus one as each stage begins
      %                            (default 50)
      %     'HoldTime', s          held at the top (default 1)
      %     'Timeout', s           the deadline of the whole call (default the client's Timeout)
      %   result is a struct of time series, one entry per frame (N frames):
      %     time N-by-1 (s), stage N-by-1 cellstr, leftSum, rightSum N-by-1 (the pads' intensity sums),
      %     leftImages, rightImages rows-by-cols-by-N (intensities 0..4095), leftForceSum, rightForceSum
      %     N-by-3 (N, pad frames), fingerDistance (m), motorCurrent (A), fingerVelocity (m/s) N-by-1,
      %     objectPosition N-by-3 (m, world), objectOrientation N-by-4 (w x y z), axisPosition N-by-1 (m,
      %     the z axis joint), currentLimit N-by-1 (A, the force controller's output); tactileSetpoint,
      %     liftHeight, coverage (the request's, zeros replaced by the defaults); leftId, rightId,
      %     gripperSensorId (the sensors read).
      %   Bad settings raise graspsim:INVALID_ARGUMENT naming the field (e.g. coverage), unknown ids
      %   graspsim:NOT_FOUND.
      defaults = struct('TactileSetpoint', 0, 'LiftHeight', 0, 'Coverage', 0, 'FrameRateHz', 0, 'HoldTime', 0, ...
                        'Timeout', obj.Timeout);
      o = graspsim.internal.parseOptions(defaults, varargin, 'runWorkCycle');
      names = {'TactileSetpoint', 'LiftHeight', 'Coverage', 'FrameRateHz', 'HoldTime', 'Timeout'};
      for k = 1:numel(names)
        value = o.(names{k});
        if ~isnumeric(value) || ~isscalar(value) || ~isreal(value)
          error('graspsim:badArgument', 'runWorkCycle: %s must be one real number', names{k});
        end
      end
      if ~(o.Timeout > 0) || ~isfinite(o.Timeout)
        error('graspsim:badArgument', 'runWorkCycle: Timeout must be a positive finite number of seconds');
      end
      request = struct('scene_id', sceneId, 'gripper_id', gripperId, 'object_id', objectId, ...
                       'tactile_setpoint', double(o.TactileSetpoint), 'lift_height', double(o.LiftHeight), ...
                       'coverage', double(o.Coverage), 'frame_rate_hz', double(o.FrameRateHz), ...
                       'hold_time', double(o.HoldTime));
      envelope = graspsim.internal.post(obj, 'TactileService', 'RunWorkCycle', request, '', double(o.Timeout));
      graspsim.internal.raiseIfError(envelope);
      frames = graspsim.internal.decode('WorkCycleProgress', field(envelope, 'responses', []));
      result = workCycleResult(frames, o);
    end
  end

  methods
    function result = planGrasps(obj, hand, varargin)
      %PLANGRASPS result = c.planGrasps(hand, name, value, ...): the grasp set of an object for a built-in hand
      %   ('schunk_pg70', 'barrett_bh8_282', 'schunk_sdh2'), planned by the server or found in its store
      %   (result.fromStore). Options:
      %     'SceneId', id, 'BodyId', id   the object: a body of a scene (the scene's other bodies are obstacles)
      %     'Method', name                'bounding_box' (default), 'grasp_points', 'centroid_circles'
      %     'Friction', mu                default 0.4 (must be > 0)
      %     'Spacing', m                  bounding-box sampling (default 0.02)
      %     'Rolls', n, 'Seed', n         default 4 and 1
      %     'MaxGrasps', n                force-closure grasps kept (default 50)
      %     'Recompute', true             plan again even when stored
      %     'Timeout', s                  the deadline of the whole call (default the client's Timeout)
      %   result: see graspsim.internal.decode('GraspSet', ...): epsilon, volume, preshape, approach, handPose
      %   (object frame), jointPositions, contacts per grasp, best first. Bad input raises
      %   graspsim:INVALID_ARGUMENT naming the field (hand, friction, ...).
      defaults = struct('SceneId', '', 'BodyId', '', 'Method', 'bounding_box', 'Friction', [], 'Spacing', [], ...
                        'Rolls', [], 'Seed', [], 'MaxGrasps', 0, 'Recompute', false, 'Timeout', obj.Timeout);
      o = graspsim.internal.parseOptions(defaults, varargin, 'planGrasps');
      request = struct('object', struct('scene_id', o.SceneId, 'body_id', o.BodyId), 'hand', hand, ...
                       'method', o.Method, 'max_grasps', double(o.MaxGrasps), 'recompute', logical(o.Recompute));
      optional = {'Friction', 'friction'; 'Spacing', 'spacing'; 'Rolls', 'rolls'; 'Seed', 'seed'};
      for k = 1:size(optional, 1)
        if ~isempty(o.(optional{k, 1}))
          request.(optional{k, 2}) = double(o.(optional{k, 1}));
        end
      end
      envelope = graspsim.internal.post(obj, 'GraspService', 'PlanGrasps', request, '', double(o.Timeout));
      graspsim.internal.raiseIfError(envelope);
      messages = items(field(envelope, 'responses', []));
      if isempty(messages)
        error('graspsim:INTERNAL', 'PlanGrasps ended without a grasp set');
      end
      result = graspsim.internal.decode('GraspSet', field(messages{end}, 'result', struct()));
    end
  end

  methods
    % --- recordings (RecordingService, docs/recording.md) -------------------------------------------------
    function recording = startRecording(obj, sceneId, name, varargin)
      %STARTRECORDING rec = c.startRecording(sceneId, name, 'Groups', {...}, 'Compression', 'zstd',
      %   'ForceTorqueJoints', {...}): starts recording the scene into an MCAP file (https://mcap.dev) in the
      %   server's recording directory, one frame per scene state (stepSimulation, pose and joint changes)
      %   until stopRecording. name is the file name, ending in '.mcap' (letters, digits, '-', '_', '.'; no
      %   folders); '' or omitted = '<sceneId>-<UTC time>.mcap'. Options:
      %     'Groups', {...}              channel groups among 'graspsim' (enough to replay the scene),
      %                                  'foxglove' (opens in Foxglove), 'ros2' (a ROS 2 bag beside the file);
      %                                  {} = all three
      %     'Compression', c             chunk compression 'zstd' (default), 'lz4' or 'none'
      %     'ForceTorqueJoints', {...}   joints whose force/torque reading is recorded too
      %   Returns the recording (see listRecordings). A scene records into one file at a time: a second start
      %   raises graspsim:ALREADY_EXISTS.
      if nargin < 3 || isempty(name)
        name = '';
      end
      o = graspsim.internal.parseOptions(struct('Groups', {{}}, 'Compression', '', 'ForceTorqueJoints', {{}}), ...
                                         varargin, 'startRecording');
      if ~ischar(name)
        error('graspsim:badArgument', 'startRecording: name must be a char row such as ''run1.mcap''');
      end
      if ~ischar(o.Compression)
        error('graspsim:badArgument', 'startRecording: Compression must be ''zstd'', ''lz4'' or ''none''');
      end
      request = struct('scene_id', sceneId, 'name', name, 'groups', {idList(o.Groups, 'Groups')}, ...
                       'compression', o.Compression, ...
                       'force_torque_joints', {idList(o.ForceTorqueJoints, 'ForceTorqueJoints')});
      recording = graspsim.internal.decode('Recording', obj.recordingCall('StartRecording', request));
    end

    function recording = stopRecording(obj, sceneId)
      %STOPRECORDING rec = c.stopRecording(sceneId): stops the scene's recording and finishes its file
      %   (summary and index written, closed). Returns the recording as finished: rec.frames states recorded,
      %   rec.bytes the file's size (see listRecordings).
      recording = graspsim.internal.decode('Recording', ...
                                           obj.recordingCall('StopRecording', struct('scene_id', sceneId)));
    end

    function recordings = listRecordings(obj)
      %LISTRECORDINGS N-by-1 struct array of the recordings, active ones first, then the files in the
      %   server's recording directory by name: name (the file name, the recording's id), sceneId, path (on
      %   the server), ros2Path (the ROS 2 bag folder, '' without the 'ros2' group), active (logical), frames
      %   (scene states recorded), messages (MCAP messages, every channel), droppedFrames (states the writer
      %   could not keep up with), bytes (file size so far), startTime, endTime (simulation time of the first
      %   and last frame, s).
      response = obj.recordingCall('ListRecordings', struct());
      recordings = graspsim.internal.decode('Recording', field(response, 'recordings', []));
    end

    function bytes = downloadRecording(obj, name, file)
      %DOWNLOADRECORDING bytes = c.downloadRecording(name, file): the bytes of a recording file (finished or
      %   still being written) as a 1-by-N uint8 row; with file, also written to that local file.
      if nargin < 3
        file = '';
      end
      envelope = graspsim.internal.post(obj, 'RecordingService', 'DownloadRecording', struct('name', name));
      graspsim.internal.raiseIfError(envelope);
      chunks = items(field(envelope, 'responses', []));
      parts = cell(1, numel(chunks));
      offset = 0;
      for k = 1:numel(chunks)
        at = number(field(chunks{k}, 'offset', 0));
        if at ~= offset
          error('graspsim:DATA_LOSS', 'downloadRecording %s: chunk %d starts at byte %d, expected %d', name, k, ...
                at, offset);
        end
        parts{k} = graspsim.internal.decodeBytes(field(chunks{k}, 'data', ''));
        offset = offset + numel(parts{k});
      end
      bytes = [zeros(1, 0, 'uint8'), parts{:}];
      if ~isempty(file)
        fid = fopen(file, 'w');
        if fid < 0
          error('graspsim:badArgument', 'downloadRecording: cannot write %s', file);
        end
        fwrite(fid, bytes, 'uint8');
        fclose(fid);
      end
    end

    function replay = replayRecording(obj, name, sceneName)
      %REPLAYRECORDING replay = c.replayRecording(name, sceneName): a new scene built from a recording (the
      %   recorded scene's edits, then its first recorded state). sceneName '' or omitted = 'replay of <name>'.
      %   Returns replay.sceneId (the new scene), frames and frameTimes (frames-by-1, the simulation time of
      %   each recorded frame, s); seekReplay puts the scene into one of them.
      if nargin < 3 || isempty(sceneName)
        sceneName = '';
      end
      response = obj.recordingCall('ReplayRecording', struct('name', name, 'scene_name', sceneName));
      replay = struct('sceneId', field(response, 'scene_id', ''), 'frames', number(field(response, 'frames', 0)), ...
                      'frameTimes', reshape(double(field(response, 'frame_times', [])), [], 1));
    end

    function [time, revision] = seekReplay(obj, sceneId, name, frame)
      %SEEKREPLAY [time, revision] = c.seekReplay(sceneId, name, frame): puts a scene replayed from the
      %   recording name into the state of one recorded frame (every body, joint, velocity and contact).
      %   frame is the server's 0-BASED index: replay.frameTimes(frame + 1) is its time. Returns the scene's
      %   simulation time (s) and revision after the seek.
      if ~isnumeric(frame) || ~isscalar(frame) || ~(frame >= 0) || frame ~= round(frame)
        error('graspsim:badArgument', 'seekReplay: frame must be a whole number >= 0 (0-based)');
      end
      response = obj.recordingCall('SeekReplay', struct('scene_id', sceneId, 'name', name, 'frame', double(frame)));
      time = number(field(response, 'time', 0));
      revision = number(field(response, 'revision', 0));
    end
  end

  methods (Access = private)
    function response = recordingCall(obj, method, request)
      % A unary RecordingService call: the response message as jsondecode gives it, or error graspsim:<STATUS>.
      response = graspsim.internal.unary(obj, 'RecordingService', method, request);
    end

    function response = sceneCall(obj, method, request)
      % A unary SceneService call: the response message as jsondecode gives it, or error graspsim:<STATUS>.
      response = graspsim.internal.unary(obj, 'SceneService', method, request);
    end
  end
end

function [kind, value] = pickShape(o)
% The one shape among the addObject options, as (kind, value); an error unless exactly one is given.
given = cell(0, 2);
if ~isempty(o.Builtin), given(end + 1, :) = {'builtin', o.Builtin}; end
if ~isempty(o.Box), given(end + 1, :) = {'box', o.Box}; end
if ~isempty(o.Sphere), given(end + 1, :) = {'sphere', o.Sphere}; end
if ~isempty(o.Cylinder), given(end + 1, :) = {'cylinder', o.Cylinder}; end
if ~isempty(o.Vertices) || ~isempty(o.Triangles), given(end + 1, :) = {'mesh', {o.Vertices, o.Triangles}}; end
if ~isempty(o.MeshFile), given(end + 1, :) = {'meshFile', o.MeshFile}; end
if size(given, 1) ~= 1
  error('graspsim:badArgument', ...
        'addObject: give exactly one shape (Builtin, Box, Sphere, Cylinder, Vertices+Triangles, MeshFile), got %d', ...
        size(given, 1));
end
kind = given{1, 1};
value = given{1, 2};
counts = struct('box', 3, 'sphere', 1, 'cylinder', 2);
if isfield(counts, kind) && numel(value) ~= counts.(kind)
  error('graspsim:badArgument', 'addObject: %s needs %d value(s), got %d', kind, counts.(kind), numel(value));
end
if strcmp(kind, 'mesh') && (isempty(o.Vertices) || isempty(o.Triangles))
  error('graspsim:badArgument', 'addObject: an inline mesh needs both Vertices (N-by-3) and Triangles (M-by-3)');
end
end

function inertial = makeInertial(kind, value, mass, inertia, centerOfMass)
% The Inertial message, or [] when no mass is given (a builtin keeps its own; a shape needs one and the
% server says so).
inertial = [];
if isempty(mass)
  if ~isempty(inertia) || ~isempty(centerOfMass)
    error('graspsim:badArgument', 'addObject: Inertia and CenterOfMass need a Mass (kg)');
  end
  return;
end
if isempty(inertia)
  [centerOfMass, inertia] = graspsim.internal.shapeInertia(kind, value, mass, centerOfMass);
end
if ~isequal(size(inertia), [3 3])
  error('graspsim:badArgument', 'addObject: Inertia must be 3-by-3 (kg m^2), got %s', mat2str(size(inertia)));
end
inertia = double(inertia);
if any(any(abs(inertia - inertia.') > 1e-12 * max([1; abs(inertia(:))])))
  error('graspsim:badArgument', 'addObject: Inertia must be symmetric, got %s', mat2str(inertia));
end
inertial = struct('mass', double(mass), 'ixx', inertia(1, 1), 'iyy', inertia(2, 2), 'izz', inertia(3, 3), ...
                  'ixy', inertia(1, 2), 'ixz', inertia(1, 3), 'iyz', inertia(2, 3));
if ~isempty(centerOfMass)
  inertial.center_of_mass = graspsim.internal.toVec3(centerOfMass, 'CenterOfMass');
end
end

function result = workCycleResult(frames, o)
% The time series of decoded WorkCycleProgress frames (see runWorkCycle); o holds the request's settings.
n = numel(frames);
defaultOf = @(value, default) value + (value == 0) * default;
result = struct('time', zeros(n, 1), 'stage', {cell(n, 1)}, 'leftSum', zeros(n, 1), 'rightSum', zeros(n, 1), ...
                'leftImages', zeros(0, 0, n), 'rightImages', zeros(0, 0, n), ...
                'leftForceSum', zeros(n, 3), 'rightForceSum', zeros(n, 3), ...
                'fingerDistance', zeros(n, 1), 'motorCurrent', zeros(n, 1), 'fingerVelocity', zeros(n, 1), ...
                'objectPosition', zeros(n, 3), 'objectOrientation', zeros(n, 4), ...
                'axisPosition', zeros(n, 1), 'currentLimit', zeros(n, 1), ...
                'tactileSetpoint', defaultOf(double(o.TactileSetpoint), 60000), ...
                'liftHeight', defaultOf(double(o.LiftHeight), 0.05), 'coverage', defaultOf(double(o.Coverage), 1), ...
                'leftId', '', 'rightId', '', 'gripperSensorId', '');
for k = 1:n
  f = frames(k);
  kinds = {f.readings.kind};
  pads = f.readings(strcmp(kinds, 'tactile'));
  grippers = f.readings(strcmp(kinds, 'gripper'));
  if numel(pads) ~= 2 || numel(grippers) ~= 1
    error('graspsim:INTERNAL', ['work-cycle frame at t = %g s (%s): %d tactile and %d gripper readings, ' ...
                                'expected 2 and 1'], f.time, f.stage, numel(pads), numel(grippers));
  end
  if k == 1
    result.leftImages = zeros(pads(1).rows, pads(1).cols, n);
    result.rightImages = zeros(pads(2).rows, pads(2).cols, n);
    result.leftId = pads(1).sensorId;
    result.rightId = pads(2).sensorId;
    result.gripperSensorId = grippers.sensorId;
  end
  if ~isequal(size(pads(1).intensities), size(result.leftImages(:, :, 1))) || ...
     ~isequal(size(pads(2).intensities), size(result.rightImages(:, :, 1)))
    error('graspsim:INTERNAL', 'work cycle: tactile readings of different shapes at t = %g s', f.time);
  end
  result.time(k) = f.time;
  result.stage{k} = f.stage;
  result.leftSum(k) = pads(1).intensitySum;
  result.rightSum(k) = pads(2).intensitySum;
  result.leftImages(:, :, k) = pads(1).intensities;
  result.rightImages(:, :, k) = pads(2).intensities;
  result.leftForceSum(k, :) = pads(1).forceSum;
  result.rightForceSum(k, :) = pads(2).forceSum;
  result.fingerDistance(k) = grippers.fingerDistance;
  result.motorCurrent(k) = grippers.motorCurrent;
  result.fingerVelocity(k) = grippers.fingerVelocity;
  result.objectPosition(k, :) = f.objectPose(1:3);
  result.objectOrientation(k, :) = f.objectPose(4:7);
  result.axisPosition(k) = f.axisPosition;
  result.currentLimit(k) = f.currentLimit;
end
end

function ids = idList(ids, what)
% Ids as a 1-by-N cellstr (a char row is one id).
if ischar(ids)
  ids = {ids};
end
if isempty(ids)
  ids = {};
end
if ~iscellstr(ids)
  error('graspsim:badArgument', '%s must be a char row or a cellstr of ids', what);
end
ids = reshape(ids, 1, []);
end

function value = field(msg, name, default)
% msg.(name), or default when absent.
if isstruct(msg) && isfield(msg, name)
  value = msg.(name);
else
  value = default;
end
end

function value = number(x)
% A double from a JSON number or from the string protobuf uses for a 64-bit integer.
if ischar(x)
  value = str2double(x);
elseif isempty(x)
  value = 0;
else
  value = double(x);
end
end

function list = items(x)
% A decoded JSON array as an N-by-1 cell array (jsondecode gives a struct array, a cell array or []).
if isempty(x)
  list = cell(0, 1);
elseif iscell(x)
  list = x(:);
else
  list = num2cell(x(:));
end
end

function list = stringList(x)
% A decoded JSON array of strings as an N-by-1 cellstr.
if isempty(x)
  list = cell(0, 1);
elseif ischar(x)
  list = {x};
else
  list = x(:);
end
end

function row = matchName(name, names, caller)
% The index of name among names, ignoring case and underscores (TimeStep, timeStep, time_step); an error if none.
row = [];
if ischar(name)
  row = find(strcmp(lower(strrep(name, '_', '')), lower(names)), 1);
end
if isempty(row)
  if ischar(name)
    text = ['''' name ''''];
  else
    text = ['of class ' class(name)];
  end
  error('graspsim:badArgument', '%s: unknown parameter %s; known: %s', caller, text, strjoin(names(:).', ', '));
end
end

function name = integratorName(value)
% The Integrator enum name of 'linearly_implicit_euler', 'semi_implicit_euler', 'velocity_verlet' or
% 'runge_kutta_4' (any case, with or without the INTEGRATOR_ prefix).
known = {'linearly_implicit_euler', 'semi_implicit_euler', 'velocity_verlet', 'runge_kutta_4'};
if ischar(value)
  value = lower(value);
  if strncmp(value, 'integrator_', 11)
    value = value(12:end);
  end
end
if ~ischar(value) || ~any(strcmp(value, known))
  error('graspsim:badArgument', 'Integrator must be one of %s', strjoin(known, ', '));
end
name = ['INTEGRATOR_' upper(value)];
end

function message = contactMessage(value, what)
% A ContactDefaults message (snake_case fields) from a struct with the fields stiffness, damping,
% bristleStiffness, bristleDamping, viscousFriction, stribeckVelocity (any case, underscores allowed); empty
% fields are left out (the default).
known = {'Stiffness', 'stiffness'; 'Damping', 'damping'; 'BristleStiffness', 'bristle_stiffness'; ...
         'BristleDamping', 'bristle_damping'; 'ViscousFriction', 'viscous_friction'; ...
         'StribeckVelocity', 'stribeck_velocity'};
if ~isstruct(value) || ~isscalar(value)
  error('graspsim:badArgument', '%s must be a struct with fields among %s', what, strjoin(known(:, 1).', ', '));
end
message = struct();
names = fieldnames(value);
for k = 1:numel(names)
  row = matchName(names{k}, known(:, 1), what);
  v = value.(names{k});
  if isempty(v)
    continue;
  end
  if ~isnumeric(v) || ~isscalar(v) || ~isreal(v)
    error('graspsim:badArgument', '%s.%s must be one real number', what, names{k});
  end
  message.(known{row, 2}) = double(v);
end
end

function list = importWarnings(x)
% ImportWarning messages as an N-by-1 struct array (element, value, action).
list = struct('element', {}, 'value', {}, 'action', {});
entries = items(x);
for k = 1:numel(entries)
  w = entries{k};
  list(end + 1, 1) = struct('element', field(w, 'element', ''), 'value', field(w, 'value', ''), ...
                            'action', field(w, 'action', '')); %#ok<AGROW>
end
end

function options = importOptions(source, density, strict, modelName, caller)
% The ImportOptions message: inertia source 'auto' | 'from_file' | 'from_geometry', density kg/m^3 ([] = the
% server's 1000), strict, the SDF model name.
sources = struct('auto', 'INERTIA_SOURCE_AUTO', 'from_file', 'INERTIA_SOURCE_FROM_FILE', ...
                 'from_geometry', 'INERTIA_SOURCE_FROM_GEOMETRY');
if ~ischar(source) || ~isfield(sources, source)
  error('graspsim:badArgument', '%s: the inertia source must be ''auto'', ''from_file'' or ''from_geometry''', caller);
end
options = struct('inertia', sources.(source), 'strict', logical(strict), 'model_name', modelName);
if ~isempty(density)
  options.density = double(density);
end
end
