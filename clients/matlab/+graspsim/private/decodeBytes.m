function bytes = decodeBytes(text)
%DECODEBYTES The uint8 column of a base64 string (a protobuf bytes field in JSON).
if isempty(text)
  bytes = zeros(0, 1, 'uint8');
else
  bytes = reshape(uint8(matlab.net.base64decode(text)), [], 1);
end
end
