function list = items(x)
%ITEMS The elements of a decoded JSON array of objects as an N-by-1 cell array of structs.
%   jsondecode gives a struct array when the objects have the same fields, a cell array when they differ
%   (e.g. different oneof members) and [] for an empty array.
if isempty(x)
  list = cell(0, 1);
elseif iscell(x)
  list = x(:);
else
  list = num2cell(x(:));
end
end
