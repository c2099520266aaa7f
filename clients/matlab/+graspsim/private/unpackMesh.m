function [vertices, triangles] = unpackMesh(msg)
%UNPACKMESH vertices N-by-3 double (m, exact copies of the float32 values) and triangles M-by-3 double of
%   0-based vertex indices from a decoded MeshData.
v = decodePacked(getField(msg, 'vertices', ''), 'single');
t = decodePacked(getField(msg, 'triangles', ''), 'uint32');
vertices = reshape(double(v), 3, []).';
triangles = reshape(double(t), 3, []).';
end
