function bytes = decodeBytes(text)
%DECODEBYTES A 1-by-N uint8 row from the base64 string of a protobuf bytes field in JSON ('' or [] = empty).
if isempty(text)
  bytes = zeros(1, 0, 'uint8');
else
  bytes = reshape(uint8(matlab.net.base64decode(text)), 1, []);
end
end
