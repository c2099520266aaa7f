function value = getField(s, name, default)
%GETFIELD s.(name), or default when s is not a struct or has no such field (protobuf omits unset messages).
if isstruct(s) && isfield(s, name)
  value = s.(name);
else
  value = default;
end
end
