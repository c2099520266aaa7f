function response = unary(client, service, method, request)
%UNARY A unary call: the response message as decoded by jsondecode, or an error graspsim:<STATUS>.
envelope = post(client, service, method, request);
raiseIfError(envelope);
response = envelope.response;
end
