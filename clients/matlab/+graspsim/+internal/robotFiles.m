function [format, text, scenePaths, localPaths] = robotFiles(file, packageRoots)
%ROBOTFILES The format and text of a local robot file and the mesh files its collision geometry needs.
%   [format, text, scenePaths, localPaths] = robotFiles('robot.urdf', packageRoots)
%   format is 'urdf', 'mjcf' or 'sdf' (from the extension .urdf / .xml .mjcf / .sdf .world, else the root
%   element <robot> / <mujoco> / <sdf>). scenePaths{k} is the path the server looks localPaths{k} up by, as the
%   Python client's graspsim._robot_files does (docs/import.md):
%     package://pkg/a/b.stl -> a/b.stl,  model://m/a/b.stl -> m/a/b.stl,  file:///x/b.stl -> b.stl,
%     ../meshes/b.stl -> meshes/b.stl   (normalised; leading ./ and ../ dropped; absolute paths: the base name).
%   Meshes: URDF <collision> <mesh filename>; MJCF <asset> <mesh file> under <compiler meshdir|assetdir>
%   (<include> is not followed here); SDF <collision> <mesh><uri>.
%   packageRoots: [] (the file's folder and its parents), a struct or containers.Map {pkg: folder}, or a
%   cellstr of folders that hold package folders. Every referenced file missing on disk is named in one graspsim:missingFiles error.
if ~exist(file, 'file')
  error('graspsim:badArgument', 'addRobot Path: no such file ''%s''', file);
end
fid = fopen(file, 'r');
text = fread(fid, Inf, '*char').';
fclose(fid);
file = absolutePath(file);
base = fileparts(file);
format = detectFormat(file, text);
body = regexprep(text, '<!--.*?-->', '');
refs = {};
keys = {};
switch format
  case 'urdf'
    for block = regexp(body, '<collision\>.*?</collision>', 'match')
      for m = regexp(block{1}, '<mesh\>[^>]*?\sfilename\s*=\s*("[^"]*"|''[^'']*'')', 'tokens')
        refs{end + 1} = unquote(m{1}{1}); %#ok<AGROW>
        keys{end + 1} = scenePath(refs{end}); %#ok<AGROW>
      end
    end
  case 'mjcf'
    meshdir = '';
    for m = regexp(body, '<compiler\>[^>]*>', 'match')
      dir = attribute(m{1}, 'meshdir');
      if isempty(dir)
        dir = attribute(m{1}, 'assetdir');
      end
      if ~isempty(dir)
        meshdir = dir;
      end
    end
    for block = regexp(body, '<asset\>.*?</asset>', 'match')
      for m = regexp(block{1}, '<mesh\>[^>]*>', 'match')
        name = attribute(m{1}, 'file');
        if ~isempty(name)
          if ~isempty(meshdir)
            name = [regexprep(meshdir, '/+$', '') '/' name];
          end
          refs{end + 1} = name; %#ok<AGROW>
          keys{end + 1} = normalise(name); %#ok<AGROW>
        end
      end
    end
  case 'sdf'
    for block = regexp(body, '<collision\>.*?</collision>', 'match')
      for m = regexp(block{1}, '<mesh\>.*?<uri>\s*(.*?)\s*</uri>', 'tokens')
        refs{end + 1} = m{1}{1}; %#ok<AGROW>
        keys{end + 1} = scenePath(refs{end}); %#ok<AGROW>
      end
    end
end
scenePaths = {};
localPaths = {};
missing = {};
for k = 1:numel(refs)
  [found, tried] = resolve(refs{k}, base, packageRoots);
  if isempty(found)
    missing{end + 1} = sprintf('  ''%s'': looked for %s', refs{k}, tried); %#ok<AGROW>
  elseif ~any(strcmp(keys{k}, scenePaths))
    scenePaths{end + 1} = keys{k}; %#ok<AGROW>
    localPaths{end + 1} = found; %#ok<AGROW>
  end
end
if ~isempty(missing)
  error('graspsim:missingFiles', '%s: %d referenced file(s) not found on disk:\n%s', file, numel(missing), ...
        strjoin(missing, sprintf('\n')));
end
end

function format = detectFormat(file, text)
[~, ~, ext] = fileparts(file);
switch lower(ext)
  case '.urdf'
    format = 'urdf';
    return
  case {'.xml', '.mjcf'}
    format = 'mjcf';
    return
  case {'.sdf', '.world'}
    format = 'sdf';
    return
end
root = regexp(regexprep(text, '<!--.*?-->|<\?.*?\?>', ''), '<([A-Za-z_][\w.-]*)', 'tokens', 'once');
tags = struct('robot', 'urdf', 'mujoco', 'mjcf', 'sdf', 'sdf');
if isempty(root) || ~isfield(tags, root{1})
  error('graspsim:badArgument', '%s: the root element is none of <robot> (URDF), <mujoco> (MJCF), <sdf> (SDF)', file);
end
format = tags.(root{1});
end

function value = attribute(element, name)
token = regexp(element, ['\s' name '\s*=\s*("[^"]*"|''[^'']*'')'], 'tokens', 'once');
if isempty(token)
  value = '';
else
  value = unquote(token{1});
end
end

function s = unquote(s)
s = strtrim(s(2:end - 1));
end

function key = scenePath(ref)
ref = strtrim(ref);
if strncmp(ref, 'package://', 10)
  rest = ref(11:end);
  slash = find(rest == '/', 1);
  if ~isempty(slash)
    rest = rest(slash + 1:end);
  end
  ref = rest;
elseif strncmp(ref, 'model://', 8)
  ref = ref(9:end);
elseif strncmp(ref, 'file://', 7)
  ref = ref(8:end);
end
key = normalise(ref);
end

function key = normalise(path)
% posixpath.normpath, then leading '.' and '..' dropped; an absolute path becomes its base name.
absolute = ~isempty(path) && path(1) == '/';
parts = strsplit(path, '/');
out = {};
for k = 1:numel(parts)
  part = parts{k};
  if isempty(part) || strcmp(part, '.')
    continue
  elseif strcmp(part, '..') && ~isempty(out) && ~strcmp(out{end}, '..')
    out(end) = [];
  else
    out{end + 1} = part; %#ok<AGROW>
  end
end
if absolute
  key = '';
  if ~isempty(out)
    key = out{end};
  end
  return
end
while ~isempty(out) && strcmp(out{1}, '..')
  out(1) = [];
end
key = strjoin(out, '/');
end

function [found, tried] = resolve(ref, base, packageRoots)
ref = strtrim(ref);
found = '';
schemes = {'package://', 'model://'};
for s = 1:2
  if strncmp(ref, schemes{s}, numel(schemes{s}))
    rest = ref(numel(schemes{s}) + 1:end);
    slash = find(rest == '/', 1);
    if isempty(slash)
      pkg = rest;
      rest = '';
    else
      pkg = rest(1:slash - 1);
      rest = rest(slash + 1:end);
    end
    [dir, tried] = packageDir(pkg, base, packageRoots);
    if isempty(dir)
      return
    end
    tried = fullfile(dir, rest);
    if exist(tried, 'file') == 2
      found = tried;
    end
    return
  end
end
if strncmp(ref, 'file://', 7)
  ref = ref(8:end);
end
if ~isempty(ref) && ref(1) == '/'
  tried = ref;
  if exist(ref, 'file') == 2
    found = ref;
    return
  end
  beside = fullfile(base, ref(2:end));  % as PyBullet does: '/meshes/a.stl' next to the file
  tried = [ref ' or ' beside];
  if exist(beside, 'file') == 2
    found = beside;
  end
  return
end
tried = fullfile(base, ref);
if exist(tried, 'file') == 2
  found = tried;
end
end

function [dir, tried] = packageDir(pkg, base, packageRoots)
dir = '';
if isa(packageRoots, 'containers.Map')
  if isKey(packageRoots, pkg)
    dir = packageRoots(pkg);
    tried = '';
  else
    tried = sprintf('PackageRoots(''%s'') (not given)', pkg);
  end
  return
end
if isstruct(packageRoots)
  if isfield(packageRoots, pkg)
    dir = packageRoots.(pkg);
    tried = '';
  else
    tried = sprintf('PackageRoots.%s (not given)', pkg);
  end
  return
end
if isempty(packageRoots)
  roots = {};
  d = base;
  while true
    roots{end + 1} = d; %#ok<AGROW>
    parent = fileparts(d);
    if isempty(parent) || strcmp(parent, d)
      break
    end
    d = parent;
  end
  where = 'the file''s folder and its parents';
else
  roots = cellstr(packageRoots);
  where = ['PackageRoots ' strjoin(roots, ', ')];
end
for k = 1:numel(roots)
  if exist(fullfile(roots{k}, pkg), 'dir') == 7
    dir = fullfile(roots{k}, pkg);
    tried = '';
    return
  end
  [~, last] = fileparts(roots{k});
  if strcmp(last, pkg)  % the file lies inside the package: .../pkg/urdf/robot.urdf
    dir = roots{k};
    tried = '';
    return
  end
end
tried = sprintf('a folder ''%s'' in %s', pkg, where);
end

function path = absolutePath(path)
if isempty(path) || (path(1) ~= '/' && ~(numel(path) > 1 && path(2) == ':'))
  path = fullfile(pwd, path);
end
end
