function list = stringList(x)
%STRINGLIST A decoded JSON array of strings (or a char row, or []) as an N-by-1 cellstr.
if isempty(x)
  list = cell(0, 1);
elseif ischar(x)
  list = {x};
else
  list = x(:);
end
end
