function options = parseOptions(defaults, args, caller)
%PARSEOPTIONS Name-value pairs (names case-insensitive) over a struct of defaults; unknown names are errors.
options = defaults;
names = fieldnames(defaults);
if mod(numel(args), 2) ~= 0
  error('graspsim:badArgument', '%s: options come in name-value pairs', caller);
end
for k = 1:2:numel(args)
  match = [];
  if ischar(args{k})
    match = find(strcmpi(args{k}, names), 1);
  end
  if isempty(match)
    error('graspsim:badArgument', '%s: unknown option %s; known: %s', caller, toText(args{k}), strjoin(names.', ', '));
  end
  options.(names{match}) = args{k + 1};
end
end

function text = toText(value)
if ischar(value)
  text = ['''' value ''''];
else
  text = ['of class ' class(value)];
end
end
