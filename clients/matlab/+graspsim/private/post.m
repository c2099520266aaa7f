function envelope = post(client, service, method, request, query)
%POST One call through the server's HTTP/JSON gateway; returns the decoded envelope without checking it.
%   Every call asks for ?envelope=1, so the HTTP status is always 200 and the body says the gRPC status:
%   {"code": 0, "status": "OK", "message": "", "response": {...}} (or "responses": [...] for a stream).
%   timeout_s gives the server the same deadline as the client; the HTTP timeout waits 5 s longer so the
%   server's DEADLINE_EXCEEDED arrives before the client gives up. query is more '&name=value' text, or ''.
if nargin < 5
  query = '';
end
url = sprintf('%s/v1/%s/%s?envelope=1&timeout_s=%.17g%s', client.Url, service, method, client.Timeout, query);
body = toJson(request);
try
  if isOctave()
    % Octave's webwrite sends only forms: the gateway reads the JSON from the field payload=<json>.
    options = weboptions('Timeout', client.Timeout + 5, 'ContentType', 'text');
    text = webwrite(url, 'payload', body, options);
  else
    options = weboptions('MediaType', 'application/json', 'Timeout', client.Timeout + 5, 'ContentType', 'text');
    text = webwrite(url, body, options);
  end
catch err
  error('graspsim:UNAVAILABLE', 'no answer from the graspsim HTTP gateway at %s (%s/%s): %s', ...
        client.Url, service, method, err.message);
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
