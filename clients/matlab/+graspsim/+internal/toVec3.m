function msg = toVec3(values, what)
%TOVEC3 A graspsim.v1.Vec3 message from 3 numbers.
values = double(values(:).');
if numel(values) ~= 3
  error('graspsim:badArgument', '%s needs 3 values, got %d', what, numel(values));
end
msg = struct('x', values(1), 'y', values(2), 'z', values(3));
end
