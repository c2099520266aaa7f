function [centerOfMass, inertia] = shapeInertia(kind, value, mass, centerOfMass)
%SHAPEINERTIA Centre of mass (1-by-3, m) and inertia tensor about it (3-by-3, kg m^2) of a uniform-density
%   shape of the given mass (kg), in the shape's frame:
%     box [a b c] (full edge lengths): diag(b^2+c^2, a^2+c^2, a^2+b^2) m/12
%     sphere r: 2/5 m r^2 about every axis
%     cylinder [r l] along z: m r^2/2 about z, m (3r^2+l^2)/12 about x and y
%     mesh {vertices, triangles}: closed mesh by the divergence theorem; its volume centroid becomes the
%       centre of mass unless one is given.
%   centerOfMass given ([] = not given) is kept for the primitives (their centroid is the origin).
m = double(mass);
switch kind
  case 'box'
    s = double(value(:).');
    inertia = diag([s(2)^2 + s(3)^2, s(1)^2 + s(3)^2, s(1)^2 + s(2)^2]) * m / 12;
  case 'sphere'
    inertia = eye(3) * 0.4 * m * double(value)^2;
  case 'cylinder'
    r = double(value(1));
    l = double(value(2));
    side = m * (3 * r^2 + l^2) / 12;
    inertia = diag([side, side, m * r^2 / 2]);
  case 'mesh'
    [centroid, inertia] = meshInertia(m, double(value{1}), double(value{2}));
    if isempty(centerOfMass)
      centerOfMass = centroid;
    end
  otherwise
    error('graspsim:badArgument', ...
          'give Inertia (3-by-3, kg m^2) with Mass for a %s object: it cannot be computed here', kind);
end
end

function [centroid, inertia] = meshInertia(mass, vertices, triangles)
% The solid is the signed sum of the tetrahedra (origin, a, b, c) over the triangles. A tetrahedron of volume
% V = det[a b c]/6 has its centroid at (a+b+c)/4 and integral of x x' dV = V/20 (a a' + b b' + c c' + s s'),
% s = a+b+c.
a = vertices(triangles(:, 1) + 1, :);
b = vertices(triangles(:, 2) + 1, :);
c = vertices(triangles(:, 3) + 1, :);
tet = sum(a .* cross(b, c, 2), 2) / 6;
volume = sum(tet);
if ~(volume > 0)
  error('graspsim:badArgument', ...
        'mesh encloses volume %g m^3: it must be closed with outward-facing (counter-clockwise) triangles', volume);
end
s = a + b + c;
centroid = sum(bsxfun(@times, tet, s), 1) / (4 * volume);
second = zeros(3);
corners = {a, b, c, s};
for k = 1:4
  p = corners{k};
  second = second + p.' * bsxfun(@times, tet / 20, p);
end
second = second - volume * (centroid.' * centroid);
inertia = (mass / volume) * (trace(second) * eye(3) - second);
end
