function out = fromGeometry(msg)
%FROMGEOMETRY One collision shape: type ('box', 'sphere', 'cylinder', 'mesh' or 'meshFile'); size (box [x y z]
%   full edges, sphere r, cylinder [r l], m; [] otherwise); vertices N-by-3 double (m) and triangles M-by-3
%   double of 0-based indices (inline meshes, filled only when the scene was read with IncludeGeometry);
%   meshFile (uploaded path); origin 1-by-7 in the body frame; scale 1-by-3.
out = struct('type', '', 'size', [], 'vertices', zeros(0, 3), 'triangles', zeros(0, 3), 'meshFile', '', ...
             'origin', fromPose(getField(msg, 'origin', struct())), ...
             'scale', fromVec3(getField(msg, 'scale', []), [1 1 1]));
if isfield(msg, 'box')
  out.type = 'box';
  out.size = fromVec3(getField(msg.box, 'size', struct()), [0 0 0]);
elseif isfield(msg, 'sphere')
  out.type = 'sphere';
  out.size = num(getField(msg.sphere, 'radius', 0));
elseif isfield(msg, 'cylinder')
  out.type = 'cylinder';
  out.size = [num(getField(msg.cylinder, 'radius', 0)), num(getField(msg.cylinder, 'length', 0))];
elseif isfield(msg, 'mesh')
  out.type = 'mesh';
  [out.vertices, out.triangles] = unpackMesh(msg.mesh);
elseif isfield(msg, 'mesh_file')
  out.type = 'meshFile';
  out.meshFile = msg.mesh_file;
end
end
