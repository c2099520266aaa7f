function msg = packMesh(vertices, triangles)
%PACKMESH A graspsim.v1.MeshData message: vertices N-by-3 (m) as packed float32, triangles M-by-3 of
%   0-based vertex indices (counter-clockwise seen from outside) as packed uint32.
%   Only shapes and integrality are checked here (a cast would silently change the numbers); the server
%   checks the values (NaN, indices in range, empty meshes).
if size(vertices, 2) ~= 3 || ndims(vertices) ~= 2
  error('graspsim:badArgument', 'Vertices must be N-by-3 (m), got %s', mat2str(size(vertices)));
end
if size(triangles, 2) ~= 3 || ndims(triangles) ~= 2
  error('graspsim:badArgument', 'Triangles must be M-by-3 (0-based vertex indices), got %s', mat2str(size(triangles)));
end
t = double(triangles);
if any(t(:) < 0 | t(:) ~= round(t(:)) | t(:) > 4294967295)
  error('graspsim:badArgument', 'Triangles must hold 0-based vertex indices (integers >= 0)');
end
msg = struct('vertices', graspsim.internal.encodePacked(vertices, 'single'), ...
             'triangles', graspsim.internal.encodePacked(t, 'uint32'));
end
