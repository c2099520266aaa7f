function raiseIfError(envelope)
%RAISEIFERROR Raises error('graspsim:<STATUS>', message) when an envelope carries a non-OK status.
if envelope.code ~= 0
  status = envelope.status;
  if isempty(regexp(status, '^[A-Z_]+$', 'once'))
    status = 'UNKNOWN';
  end
  error(['graspsim:' status], '%s', envelope.message);
end
end
