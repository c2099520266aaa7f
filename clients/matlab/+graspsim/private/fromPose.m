function pose = fromPose(msg)
%FROMPOSE 1-by-7 [x y z qw qx qy qz] of a decoded Pose; absent position = origin, absent orientation = identity.
p = getField(msg, 'position', struct());
q = getField(msg, 'orientation', struct('w', 1));
pose = [num(getField(p, 'x', 0)), num(getField(p, 'y', 0)), num(getField(p, 'z', 0)), ...
        num(getField(q, 'w', 0)), num(getField(q, 'x', 0)), num(getField(q, 'y', 0)), num(getField(q, 'z', 0))];
end
