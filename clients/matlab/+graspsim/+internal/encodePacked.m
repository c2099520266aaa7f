function text = encodePacked(values, type)
%ENCODEPACKED base64 of values (any numeric array, read row by row) as packed little-endian numbers of class
%   type ('double', 'single', 'uint32'). Rows first: an N-by-3 array becomes x1 y1 z1 x2 y2 z2 ...
values = cast(reshape(values.', 1, []), type);
[~, ~, endian] = computer();
if endian == 'B'
  values = swapbytes(values);
end
text = graspsim.internal.encodeBytes(typecast(values, 'uint8'));
end
