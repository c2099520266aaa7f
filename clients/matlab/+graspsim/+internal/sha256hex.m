function hex = sha256hex(bytes)
%SHA256HEX Lowercase hex SHA-256 of a uint8 array: Octave's hash(), else Java's MessageDigest (MATLAB).
bytes = reshape(uint8(bytes), 1, []);
if graspsim.internal.isOctave()
  hex = lower(hash('sha256', char(bytes)));
  return;
end
if ~usejava('jvm')
  error('graspsim:badArgument', 'SHA-256 needs Octave''s hash() or MATLAB with Java (start without -nojvm)');
end
digest = java.security.MessageDigest.getInstance('SHA-256');
if ~isempty(bytes)
  digest.update(typecast(bytes, 'int8'));
end
raw = typecast(int8(digest.digest()), 'uint8');
hex = lower(reshape(dec2hex(raw, 2).', 1, []));
end
