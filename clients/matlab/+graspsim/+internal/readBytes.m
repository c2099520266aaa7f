function bytes = readBytes(data, what)
%READBYTES File content as a uint8 column: data is the content (uint8/int8 array) or a local file name (char).
if ischar(data)
  fid = fopen(data, 'r');
  if fid < 0
    error('graspsim:badArgument', '%s: cannot open the local file ''%s''', what, data);
  end
  bytes = fread(fid, Inf, '*uint8');
  fclose(fid);
elseif isa(data, 'uint8')
  bytes = data(:);
elseif isa(data, 'int8')
  bytes = typecast(data(:), 'uint8');
else
  error('graspsim:badArgument', '%s: give the content as uint8 or the name of a local file, not %s', what, class(data));
end
end
