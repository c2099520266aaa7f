function msg = toPose(pose, what)
%TOPOSE A graspsim.v1.Pose message from 7 numbers [x y z qw qx qy qz] (m; unit quaternion w, x, y, z).
%   Only the count is checked here: the server validates the values (NaN, quaternion norm) and names the field.
pose = double(pose(:).');
if numel(pose) ~= 7
  error('graspsim:badArgument', '%s needs 7 values [x y z qw qx qy qz], got %d', what, numel(pose));
end
msg = struct('position', struct('x', pose(1), 'y', pose(2), 'z', pose(3)), ...
             'orientation', struct('w', pose(4), 'x', pose(5), 'y', pose(6), 'z', pose(7)));
end
