function response = unary(client, service, method, request)
%UNARY A unary call: the response message as decoded by jsondecode, or an error graspsim:<STATUS>.
envelope = graspsim.internal.post(client, service, method, request);
graspsim.internal.raiseIfError(envelope);
response = envelope.response;
end
