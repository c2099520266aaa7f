function name = enumName(value, prefix)
%ENUMNAME A protobuf enum name without its prefix, in lower case: ('BODY_MOTION_FREE', 'BODY_MOTION_') -> 'free'.
if ~ischar(value)
  value = sprintf('%d', value);
end
if strncmp(value, prefix, numel(prefix))
  value = value(numel(prefix) + 1:end);
end
name = lower(value);
end
