function envelope = post(client, service, method, request, query, timeout)
%POST One call through the server's HTTP/JSON gateway; returns the decoded envelope without checking it.
%   Every call asks for ?envelope=1, so the HTTP status is always 200 and the body says the gRPC status:
%   {"code": 0, "status": "OK", "message": "", "response": {...}} (or "responses": [...] for a stream).
%   timeout_s gives the server the same deadline as the client; the HTTP timeout waits 5 s longer so the
%   server's DEADLINE_EXCEEDED arrives before the client gives up. query is more '&name=value' text, or ''.
%   request is a struct (or cell array, for a client stream) or JSON text as it is.
if nargin < 5
  query = '';
end
if nargin < 6
  timeout = client.Timeout;
end
url = sprintf('%s/v1/%s/%s?envelope=1&timeout_s=%.17g%s', client.Url, service, method, timeout, query);
if ischar(request)
  body = request;
else
  body = graspsim.internal.toJson(request);
end
headers = {};
if ~isempty(client.Token)
  headers = {'Authorization', ['Bearer ' client.Token]};  % checked by the server like any gRPC call's
end
scene = sceneOf(request);
if ~isempty(scene)
  headers(end + 1:end + 2) = {'graspsim-scene-id', scene};  % a fleet's balancer routes by it (docs/scaling.md)
end
try
  if graspsim.internal.isOctave()
    % Octave's webwrite sends only forms: the gateway reads the JSON from the field payload=<json>.
    options = withHeaders(weboptions('Timeout', timeout + 5, 'ContentType', 'text'), headers);
    text = webwrite(url, 'payload', body, options);
  else
    options = withHeaders(weboptions('MediaType', 'application/json', 'Timeout', timeout + 5, ...
                                     'ContentType', 'text'), headers);
    text = webwrite(url, body, options);
  end
catch err
  transportError(err, client.Url, service, method, numel(body));
end
if ~ischar(text)
  text = char(text(:).');
end
try
  envelope = jsondecode(text);
catch err
  error('graspsim:INTERNAL', '%s/%s: the reply is not JSON (%s): %s', service, method, err.message, ...
        text(1:min(end, 200)));
end
if ~isstruct(envelope) || ~isfield(envelope, 'code') || ~isfield(envelope, 'status')
  error('graspsim:INTERNAL', '%s/%s: the reply is not a status envelope: %s', service, method, text(1:min(end, 200)));
end
end

function options = withHeaders(options, headers)
% Only a call with a token sets HeaderFields (an empty cell is not a valid value everywhere).
if ~isempty(headers)
  options.HeaderFields = headers;
end
end

function transportError(err, url, service, method, bytes)
% Raises the error of a request that got no status envelope back. With envelope=1 the gateway answers 200
% to every call it handles, so an HTTP error status comes from the HTTP layer itself (e.g. 413 for a body
% above its limit); Octave's webwrite drops that status and body.
where = sprintf('%s (%s/%s, %d-byte request)', url, service, method, bytes);
text = lower(err.message);
if ~isempty(strfind(text, 'response code said error')) || ~isempty(strfind(lower(err.identifier), 'statuscode'))
  error('graspsim:HTTP_ERROR', 'the graspsim HTTP gateway at %s answered with an HTTP error status: %s', ...
        where, err.message);
elseif ~isempty(strfind(text, 'timeout')) || ~isempty(strfind(text, 'timed out'))
  error('graspsim:DEADLINE_EXCEEDED', 'no answer from the graspsim HTTP gateway at %s in time: %s', where, err.message);
end
error('graspsim:UNAVAILABLE', 'no answer from the graspsim HTTP gateway at %s: %s', where, err.message);
end

function id = sceneOf(request)
% The scene a request is about: its scene_id or add_to_scene_id, or its object's (PlanGrasps, EvaluateGrasp);
% the first message's for a client stream. '' when none.
id = '';
if iscell(request) && ~isempty(request)
  request = request{1};
end
if ~isstruct(request) || isempty(request)
  return;
end
for name = {'scene_id', 'add_to_scene_id'}
  if isfield(request, name{1}) && ischar(request.(name{1})) && ~isempty(request.(name{1}))
    id = request.(name{1});
    return;
  end
end
if isfield(request, 'object') && isstruct(request.object)
  id = sceneOf(request.object);
end
end
