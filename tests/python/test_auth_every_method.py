"""Issue 24: every method of every service the server serves is called with an empty request, without a token,
with an unknown token, with a viewer token and with an admin token, and must be refused or let through exactly as
the role table says (docs/security.md, Roles). The methods come from the generated descriptors, never from a
hand-kept list, so a new RPC is covered (and must have a row in the role table) without touching this file."""
import importlib
import pkgutil
import re

import grpc
import pytest
from google.protobuf.message_factory import GetMessageClass
from grpc_health.v1 import health_pb2
from grpc_reflection.v1alpha import reflection_pb2

import graspsim.v1
from conftest import REPO_ROOT, ServerProcess

UNAUTH, DENIED, OK = grpc.StatusCode.UNAUTHENTICATED, grpc.StatusCode.PERMISSION_DENIED, grpc.StatusCode.OK
DEADLINE_S = 5.0
TOKENS = {"admin": "root-secret-0123456789abcdef", "viewer": "vera-secret-0123456789abcdef"}

# Every service with generated Python descriptors: all of graspsim.v1, plus gRPC's health and reflection.
PB2_MODULES = [importlib.import_module(f"graspsim.v1.{m.name}") for m in pkgutil.iter_modules(graspsim.v1.__path__)
               if m.name.endswith("_pb2")] + [health_pb2, reflection_pb2]
SERVICES = {s.full_name: s for module in PB2_MODULES for s in module.DESCRIPTOR.services_by_name.values()}
METHODS = {f"/{s.full_name}/{m.name}": m for s in SERVICES.values() for m in s.methods}

# The expected role of each method. docs/security.md names only some methods per role and says the full table is
# server/src/auth/role_table.cpp, "the only one", so its rows are read here with a regex. What is under test is
# the server's enforcement of the table (interceptor + each handler's RefusedCall), not the table's code path.
ROLE_TABLE = dict(re.findall(r'\{"(/[\w.]+/\w+)",\s*\{k(\w+)',
                             (REPO_ROOT / "server/src/auth/role_table.cpp").read_text()))
# Roles each caller holds enough of (viewer < scripter < admin, gateway < admin; Public needs no token).
ALLOWED = {"no token": {"Public"}, "unknown token": {"Public"}, "viewer": {"Public", "Viewer"},
           "admin": {"Public", "Viewer", "Scripter", "Gateway", "Admin"}}
REFUSAL = {"no token": UNAUTH, "unknown token": UNAUTH, "viewer": DENIED}
CALLER_TOKEN = {"no token": None, "unknown token": "unknown-secret-0123456789abcdef", **TOKENS}


def proto_methods():
    """Full names of the RPCs declared in proto/graspsim/v1/*.proto (to catch stale generated modules)."""
    names = set()
    for path in (REPO_ROOT / "proto/graspsim/v1").glob("*.proto"):
        text = re.sub(r"//.*", "", path.read_text())
        package = re.search(r"^package\s+([\w.]+);", text, re.M).group(1)
        for service, body in re.findall(r"^service\s+(\w+)\s*\{(.*?)^\}", text, re.M | re.S):
            names |= {f"/{package}.{service}/{rpc}" for rpc in re.findall(r"\brpc\s+(\w+)\s*\(", body)}
    return names


@pytest.fixture(scope="module")
def auth_server(tmp_path_factory):
    """A server of its own with tokens on (plaintext on loopback, as docs/security.md allows)."""
    d = tmp_path_factory.mktemp("auth-every-method")
    (d / "tokens").write_text("".join(f"{role} {role}-name {secret}\n" for role, secret in TOKENS.items()))
    (d / "tokens").chmod(0o600)
    proc = ServerProcess([f"--token-file={d / 'tokens'}"], d)
    yield proc
    assert proc.stop() == 0, proc.log_tail()


def call(channel, name, token):
    """Calls method `name` once with an empty request; (status code, details). A client stream sends no message
    and half-closes at once: the role is known from the metadata, so a refusal must not wait for a first message
    (a stream that checks only on reading one runs for a caller who never sends any). A server stream that
    answers a first message is reported as OK: the call ran."""
    method = METHODS[name]
    request = GetMessageClass(method.input_type)()
    shape = f"{'stream' if method.client_streaming else 'unary'}_{'stream' if method.server_streaming else 'unary'}"
    rpc = getattr(channel, shape)(name, request_serializer=type(request).SerializeToString)
    metadata = [("authorization", f"Bearer {token}")] if token else None
    try:
        answer = rpc(iter(()) if method.client_streaming else request, timeout=DEADLINE_S, metadata=metadata)
        if method.server_streaming:
            try:
                next(answer)
            except StopIteration:
                return answer.code(), answer.details()
            answer.cancel()
            return OK, "streamed a message"
        return OK, "answered"
    except grpc.RpcError as err:
        return err.code(), err.details()


def served_methods(channel):
    """Every method of every service the server lists through reflection (asked with the admin token)."""
    listing = reflection_pb2.ServerReflectionRequest(list_services="")
    stub = channel.stream_stream("/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
                                 request_serializer=reflection_pb2.ServerReflectionRequest.SerializeToString,
                                 response_deserializer=reflection_pb2.ServerReflectionResponse.FromString)
    reply = next(stub(iter([listing]), timeout=DEADLINE_S, metadata=[("authorization", f"Bearer {TOKENS['admin']}")]))
    served = {s.name for s in reply.list_services_response.service}
    assert served <= SERVICES.keys(), f"served without Python descriptors: {served - SERVICES.keys()}"
    return sorted(name for name in METHODS if name.split("/")[1] in served)


def test_descriptors_cover_the_protos_and_the_role_table_covers_every_method(auth_server):
    with grpc.insecure_channel(auth_server.address) as channel:
        served = served_methods(channel)
    assert proto_methods() <= set(served), f"declared in proto/ but not served: {proto_methods() - set(served)}"
    # A method without a row is refused by the server, but a new RPC must not pass this test unnoticed either.
    assert not set(served) - ROLE_TABLE.keys(), f"no row in role_table.cpp: {sorted(set(served) - ROLE_TABLE.keys())}"


@pytest.mark.parametrize("caller", list(ALLOWED))
def test_every_method_is_refused_or_let_through_as_the_role_table_says(auth_server, caller):
    wrong = []
    with grpc.insecure_channel(auth_server.address) as channel:
        for name in served_methods(channel):
            role = ROLE_TABLE.get(name)
            code, details = call(channel, name, CALLER_TOKEN[caller])
            answer = f"{code.name} ({details})" if details else code.name
            if role is None:
                wrong.append(f"{name}: no row in the role table (answered {code.name})")
            elif role in ALLOWED[caller]:
                # Let through: the empty request may fail (INVALID_ARGUMENT, NOT_FOUND, ...), but not on auth.
                if code in (UNAUTH, DENIED):
                    wrong.append(f"{name}: {answer}, but role {role} lets {caller} call it")
            elif code != REFUSAL[caller]:
                wrong.append(f"{name}: {answer}, expected {REFUSAL[caller].name} (needs {role})")
    assert not wrong, f"{caller}: {len(wrong)} method(s) answered against the role table:\n" + "\n".join(wrong)
