function tf = isOctave()
%ISOCTAVE True when running in GNU Octave, false in MATLAB.
persistent cached
if isempty(cached)
  cached = exist('OCTAVE_VERSION', 'builtin') ~= 0;
end
tf = cached;
end
