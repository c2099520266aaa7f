function out = fromFileInfo(msg)
%FROMFILEINFO A file held by a scene: path, size (bytes, double), sha256 (lowercase hex).
out = struct('path', getField(msg, 'path', ''), 'size', num(getField(msg, 'size', 0)), ...
             'sha256', getField(msg, 'sha256', ''));
end
