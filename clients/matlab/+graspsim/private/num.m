function value = num(x)
%NUM A double from a JSON number or from the string form protobuf uses for 64-bit integers and NaN/Infinity.
if ischar(x)
  value = str2double(x);
elseif isempty(x)
  value = 0;
else
  value = double(x);
end
end
