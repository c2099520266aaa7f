function text = encodeBytes(bytes)
%ENCODEBYTES The base64 string of a uint8 array (a protobuf bytes field in JSON).
if isempty(bytes)
  text = '';
else
  text = char(matlab.net.base64encode(reshape(uint8(bytes), 1, [])));
end
end
