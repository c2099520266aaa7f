function values = fromVec3(msg, default)
%FROMVEC3 1-by-3 [x y z] of a decoded Vec3; default (1-by-3) when the message is absent.
if ~isstruct(msg)
  values = default;
  return;
end
values = [num(getField(msg, 'x', 0)), num(getField(msg, 'y', 0)), num(getField(msg, 'z', 0))];
end
