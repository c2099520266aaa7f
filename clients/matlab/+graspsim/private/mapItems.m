function out = mapItems(convert, x)
%MAPITEMS An N-by-1 struct array of convert(element) over a decoded JSON array; 0-by-1 (same fields) if empty.
list = items(x);
out = repmat(convert(struct()), 0, 1);
for k = 1:numel(list)
  out(k, 1) = convert(list{k});
end
end
