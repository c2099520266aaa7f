function values = decodePacked(text, type)
%DECODEPACKED A column of numbers of class type ('double', 'single', 'uint32') from base64 of packed
%   little-endian values, as the API sends big arrays.
bytes = decodeBytes(text);
width = numel(typecast(zeros(1, 1, type), 'uint8'));
if mod(numel(bytes), width) ~= 0
  error('graspsim:INTERNAL', 'packed %s array of %d bytes is not a multiple of %d', type, numel(bytes), width);
end
if isempty(bytes)
  values = zeros(0, 1, type);
  return;
end
values = reshape(typecast(bytes, type), [], 1);
if bigEndianHost()
  values = swapbytes(values);
end
end

function tf = bigEndianHost()
[~, ~, endian] = computer();
tf = endian == 'B';
end
