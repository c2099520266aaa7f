function text = toJson(value)
%TOJSON JSON text of a request value, as protobuf's JSON mapping reads it.
%   A scalar struct is an object, a struct array or a cell array an array (a 1x1 cell stays an array), a char
%   row a string, a logical true/false, a numeric scalar a number and any other numeric array an array (rows
%   of a matrix nest). Doubles keep all 17 significant digits; NaN, Inf and -Inf become the strings "NaN",
%   "Infinity" and "-Infinity" that protobuf expects (jsonencode would send null or lose tiny numbers).
if isstruct(value)
  if numel(value) == 1
    names = fieldnames(value);
    parts = cell(1, numel(names));
    for k = 1:numel(names)
      parts{k} = [jsonString(names{k}) ':' graspsim.internal.toJson(value.(names{k}))];
    end
    text = ['{' strjoin(parts, ',') '}'];
  else
    parts = cell(1, numel(value));
    for k = 1:numel(value)
      parts{k} = graspsim.internal.toJson(value(k));
    end
    text = ['[' strjoin(parts, ',') ']'];
  end
elseif iscell(value)
  parts = cell(1, numel(value));
  for k = 1:numel(value)
    parts{k} = graspsim.internal.toJson(value{k});
  end
  text = ['[' strjoin(parts, ',') ']'];
elseif ischar(value)
  text = jsonString(value);
elseif islogical(value) || isnumeric(value)
  if numel(value) == 1
    text = jsonNumbers(value);
  elseif isvector(value) || isempty(value)
    text = ['[' jsonNumbers(value) ']'];
  else
    rows = cell(1, size(value, 1));
    for r = 1:size(value, 1)
      rows{r} = graspsim.internal.toJson(value(r, :));
    end
    text = ['[' strjoin(rows, ',') ']'];
  end
else
  error('graspsim:badArgument', 'cannot send a value of class %s as JSON', class(value));
end
end

function text = jsonNumbers(values)
% Comma-separated JSON numbers (or true/false) of the elements of values.
values = values(:).';
if isempty(values)
  text = '';
elseif islogical(values)
  words = {'false', 'true'};
  text = strjoin(words(double(values) + 1), ',');
elseif isinteger(values)
  text = sprintf('%d,', values);
  text = text(1:end - 1);
elseif all(isfinite(values))
  text = sprintf('%.17g,', double(values));
  text = text(1:end - 1);
else
  parts = cell(1, numel(values));
  for k = 1:numel(values)
    v = double(values(k));
    if isnan(v)
      parts{k} = '"NaN"';
    elseif isinf(v) && v > 0
      parts{k} = '"Infinity"';
    elseif isinf(v)
      parts{k} = '"-Infinity"';
    else
      parts{k} = sprintf('%.17g', v);
    end
  end
  text = strjoin(parts, ',');
end
end

function text = jsonString(s)
% A JSON string literal. Octave's char holds UTF-8 bytes, which pass as they are; MATLAB's char holds UTF-16
% code units, which are escaped as \uXXXX above 126 so that the body is plain ASCII.
s = s(:).';
codes = double(s);
special = codes < 32 | codes == 34 | codes == 92 | (codes > 126 & ~graspsim.internal.isOctave());
if ~any(special)
  text = ['"' s '"'];
  return;
end
pieces = num2cell(s);
for k = find(special)
  switch codes(k)
    case 34
      pieces{k} = '\"';
    case 92
      pieces{k} = '\\';
    case 10
      pieces{k} = '\n';
    case 13
      pieces{k} = '\r';
    case 9
      pieces{k} = '\t';
    otherwise
      pieces{k} = sprintf('\\u%04x', codes(k));
  end
end
text = ['"' pieces{:} '"'];
end
