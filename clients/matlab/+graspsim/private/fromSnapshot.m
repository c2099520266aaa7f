function out = fromSnapshot(msg)
%FROMSNAPSHOT A scene snapshot: sequence, revision (double), time (s), bodyIds (N-by-1 cellstr), poses N-by-7
%   [x y z qw qx qy qz] in the order of bodyIds, jointIds (J-by-1 cellstr), jointPositions J-by-1 (rad or m).
bodyIds = stringList(getField(msg, 'body_ids', []));
jointIds = stringList(getField(msg, 'joint_ids', []));
poses = reshape(decodePacked(getField(msg, 'body_poses', ''), 'double'), 7, []).';
positions = decodePacked(getField(msg, 'joint_positions', ''), 'double');
if size(poses, 1) ~= numel(bodyIds) || numel(positions) ~= numel(jointIds)
  error('graspsim:INTERNAL', 'snapshot with %d body ids but %d poses, %d joint ids but %d positions', ...
        numel(bodyIds), size(poses, 1), numel(jointIds), numel(positions));
end
out = struct('sequence', num(getField(msg, 'sequence', 0)), 'revision', num(getField(msg, 'revision', 0)), ...
             'time', num(getField(msg, 'time', 0)), 'bodyIds', {bodyIds}, 'poses', poses, ...
             'jointIds', {jointIds}, 'jointPositions', positions);
end
