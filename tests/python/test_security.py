"""Security end to end (docs/security.md): the real server with TLS (a CA, server and client certificates made
here with the openssl CLI), bearer tokens with roles from a token file, scene ownership and sharing, the HTTP
gateway under the same checks, mutual TLS for the hardware gateway process, and the refusal to serve a
non-loopback address without TLS."""
import hashlib
import json
import secrets
import shutil
import ssl
import subprocess
import time
import urllib.error
import urllib.request

import grpc
import pytest
from grpc_health.v1 import health_pb2, health_pb2_grpc

import graspsim
from graspsim.v1 import grasp_pb2
from graspsim.testing.gateway_rig import GatewayRig
from _support import expect_error
from conftest import REPO_ROOT as REPO, free_port, server_binary

UNAUTH = grpc.StatusCode.UNAUTHENTICATED
DENIED = grpc.StatusCode.PERMISSION_DENIED
TOKENS = {name: f"{name}-secret-{secrets.token_hex(8)}" for name in ("root", "alice", "bob", "vera", "gw")}


def openssl(*args, cwd):
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True)


def make_certs(d):
    """A CA, a server certificate for 127.0.0.1/localhost and a client certificate (CN gateway-1), all P-256."""
    ec = ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes"]
    openssl("req", "-x509", *ec, "-keyout", "ca.key", "-out", "ca.pem", "-days", "2", "-subj", "/CN=graspsim test CA",
            cwd=d)
    for name, cn, ext in [("server", "localhost", "subjectAltName=IP:127.0.0.1,DNS:localhost\nextendedKeyUsage=serverAuth"),
                          ("client", "gateway-1", "extendedKeyUsage=clientAuth")]:
        (d / f"{name}.ext").write_text(ext + "\n")
        openssl("req", "-new", *ec, "-keyout", f"{name}.key", "-out", f"{name}.csr", "-subj", f"/CN={cn}", cwd=d)
        openssl("x509", "-req", "-in", f"{name}.csr", "-CA", "ca.pem", "-CAkey", "ca.key", "-CAcreateserial",
                "-out", f"{name}.pem", "-days", "2", "-extfile", f"{name}.ext", cwd=d)
    return {name: d / f"{name}.pem" for name in ("ca", "server", "client")} | \
        {f"{name}_key": d / f"{name}.key" for name in ("server", "client")}


def data_dir_flags(d):
    """Scenes into the test's directory (--data-dir, when this build has the scene store), never the user's."""
    help_text = subprocess.run([str(server_binary()), "--help"], capture_output=True, text=True).stdout
    return [f"--data-dir={d / 'scenes'}"] if "--data-dir" in help_text else []


def hashed(secret):
    salt = secrets.token_hex(8)
    return f"sha256:{salt}:{hashlib.sha256(f'{salt}:{secret}'.encode()).hexdigest()}"


@pytest.fixture(scope="module")
def secure(tmp_path_factory):
    """One TLS server with client-certificate CA and token file; yields a dict of its addresses and files."""
    d = tmp_path_factory.mktemp("security")
    certs = make_certs(d)
    token_file = d / "tokens"
    token_file.write_text(
        "# role name token\n"
        f"admin root {TOKENS['root']}\n"
        f"scripter alice {TOKENS['alice']}\n"
        f"scripter bob {hashed(TOKENS['bob'])}   # a hashed entry\n"
        f"viewer vera {TOKENS['vera']}\n"
        f"gateway gw {TOKENS['gw']}\n"
        "grant robotiq-tcp alice\n")
    port, http_port = free_port(), free_port()
    log = d / "server.log"
    with open(log, "wb") as out:
        process = subprocess.Popen(
            [str(server_binary()), f"--listen=127.0.0.1:{port}", f"--http-listen=127.0.0.1:{http_port}",
             *data_dir_flags(d), f"--grasp-data-dir={d / 'grasps'}", f"--tls-cert={certs['server']}",
             f"--tls-key={certs['server_key']}", f"--tls-client-ca={certs['ca']}", f"--token-file={token_file}"],
            stdout=out, stderr=subprocess.STDOUT)
    info = dict(address=f"127.0.0.1:{port}", url=f"https://127.0.0.1:{http_port}", log=log, **certs)
    credentials = grpc.ssl_channel_credentials(certs["ca"].read_bytes())
    deadline = time.monotonic() + 60
    while True:
        assert process.poll() is None, log.read_text()
        try:
            with grpc.secure_channel(info["address"], credentials) as channel:
                status = health_pb2_grpc.HealthStub(channel).Check(health_pb2.HealthCheckRequest(), timeout=1).status
            if status == health_pb2.HealthCheckResponse.SERVING:
                break
        except grpc.RpcError:
            pass
        assert time.monotonic() < deadline, log.read_text()
        time.sleep(0.1)
    yield info
    process.terminate()
    assert process.wait(timeout=30) == 0, log.read_text()


def connect(secure, name=None, **kwargs):
    return graspsim.connect(secure["address"], token=TOKENS.get(name), root_certificates=secure["ca"], **kwargs)


def test_tls_handshake_works_and_plaintext_fails(secure):
    with connect(secure, "alice") as alice:
        me = alice.whoami()
        assert (me.name, me.role) == ("alice", "scripter")
    with grpc.insecure_channel(secure["address"]) as channel:
        with pytest.raises(grpc.RpcError) as info:
            health_pb2_grpc.HealthStub(channel).Check(health_pb2.HealthCheckRequest(), timeout=5)
        assert info.value.code() == grpc.StatusCode.UNAVAILABLE
    # A CA that did not sign the server's certificate: the handshake fails, nothing is served.
    with pytest.raises(graspsim.GraspsimError) as info:
        graspsim.connect(secure["address"], timeout=3, root_certificates=secure["client"])
    assert info.value.code == grpc.StatusCode.UNAVAILABLE


def test_no_token_or_a_wrong_one_is_unauthenticated(secure):
    with connect(secure) as anonymous:
        with expect_error(UNAUTH, "no bearer token"):
            anonymous.list_scenes()
    with graspsim.connect(secure["address"], token="x" * 32, root_certificates=secure["ca"]) as stranger:
        with expect_error(UNAUTH, "not valid"):
            stranger.create_scene("nope")


def test_viewer_cannot_create_a_scene(secure):
    with connect(secure, "vera") as vera:
        with expect_error(DENIED, "CreateScene needs role scripter", "'vera' is viewer"):
            vera.create_scene("mine")
        vera.list_scenes()  # reading is allowed


def test_scenes_belong_to_their_creator_until_shared(secure):
    with connect(secure, "alice") as alice, connect(secure, "bob") as bob, connect(secure, "root") as root:
        scene = alice.create_scene("alice's").id
        assert scene in [s.id for s in alice.list_scenes()]
        assert scene not in [s.id for s in bob.list_scenes()]
        assert scene in [s.id for s in root.list_scenes()]  # admin sees everything
        # Someone else's scene and a scene that does not exist get the same code and the same words.
        with pytest.raises(graspsim.GraspsimError) as foreign:
            bob.get_scene(scene)
        missing_id = "0" * len(scene) if scene != "0" * len(scene) else "1" * len(scene)
        with pytest.raises(graspsim.GraspsimError) as missing:
            bob.get_scene(missing_id)
        assert foreign.value.code == missing.value.code == DENIED
        assert foreign.value.message.replace(scene, "ID") == missing.value.message.replace(missing_id, "ID")
        with expect_error(DENIED, "does not exist or is not yours"):
            bob.delete_scene(scene)
        # A scene named inside a nested message (GraspTarget) is checked alike.
        with pytest.raises(grpc.RpcError) as nested:
            bob.grasp_stub.EvaluateGrasp(grasp_pb2.EvaluateGraspRequest(
                object=grasp_pb2.GraspTarget(scene_id=scene, body_id="cube")), timeout=30)
        assert nested.value.code() == DENIED and "is not yours" in nested.value.details()
        with expect_error(DENIED):
            bob.share_scene(scene, "bob")  # only the owner shares
        alice.share_scene(scene, "bob")
        assert bob.get_scene(scene).summary.id == scene
        assert scene in [s.id for s in bob.list_scenes()]
        with expect_error(DENIED):
            bob.delete_scene(scene)  # shared for reading only
        alice.delete_scene(scene)
        with expect_error(DENIED):
            bob.get_scene(scene)


def test_admin_adds_and_revokes_tokens(secure):
    carol = f"carol-secret-{secrets.token_hex(8)}"
    with connect(secure, "root") as root, connect(secure, "alice") as alice:
        with expect_error(DENIED, "needs role admin"):
            alice.add_token("admin", "mallory", "m" * 20)
        root.add_token("scripter", "carol", carol)
        with graspsim.connect(secure["address"], token=carol, root_certificates=secure["ca"]) as c:
            assert c.whoami().name == "carol"
            c.create_scene("carol's")
            root.revoke_token("carol")
            with expect_error(UNAUTH, "not valid"):
                c.list_scenes()
        with expect_error(grpc.StatusCode.NOT_FOUND, "carol"):
            root.revoke_token("carol")


def http(secure, method, body, token=None):
    request = urllib.request.Request(f"{secure['url']}/v1/SceneService/{method}", data=json.dumps(body).encode(),
                                     headers={"Content-Type": "application/json"})
    if token:
        request.add_header("Authorization", f"Bearer {token}")
    context = ssl.create_default_context(cafile=str(secure["ca"]))
    try:
        with urllib.request.urlopen(request, context=context, timeout=30) as reply:
            return reply.status, json.loads(reply.read())
    except urllib.error.HTTPError as err:
        return err.code, json.loads(err.read())


def test_http_gateway_is_https_and_honours_the_same_tokens(secure):
    assert http(secure, "ListScenes", {})[0] == 401
    status, reply = http(secure, "CreateScene", {"name": "v"}, TOKENS["vera"])
    assert status == 403 and reply["status"] == "PERMISSION_DENIED"
    status, scene = http(secure, "CreateScene", {"name": "h"}, TOKENS["alice"])
    assert status == 200
    scene_id = scene["summary"]["id"]
    assert http(secure, "GetScene", {"scene_id": scene_id}, TOKENS["alice"])[0] == 200
    assert http(secure, "GetScene", {"scene_id": scene_id}, TOKENS["bob"])[0] == 403
    # The viewer: a ?token= link, and then the cookie it sets.
    context = ssl.create_default_context(cafile=str(secure["ca"]))
    with urllib.request.urlopen(f"{secure['url']}/view/{scene_id}/scene.json?token={TOKENS['alice']}",
                                context=context, timeout=30) as reply:
        assert json.loads(reply.read())["summary"]["id"] == scene_id
    with pytest.raises(urllib.error.HTTPError) as err:
        urllib.request.urlopen(f"{secure['url']}/view/{scene_id}/scene.json?token={TOKENS['vera']}",
                               context=context, timeout=30)
    assert err.value.code == 403
    # Plain HTTP to the HTTPS port is not served.
    with pytest.raises((urllib.error.URLError, ConnectionError)):
        urllib.request.urlopen(secure["url"].replace("https", "http") + "/v1", timeout=10).read()


def test_gateway_process_needs_a_client_certificate(secure, tmp_path):
    with connect(secure, "alice") as alice:
        tls = [f"--tls-ca={secure['ca']}"]
        with GatewayRig(secure["address"], kinds=["robotiq-tcp"], name="no-cert", gateway_flags=tls,
                        log_path=tmp_path / "no-cert.log") as rig:
            time.sleep(2)
            assert not [d for d in alice.list_devices() if d.gateway == "no-cert"]
            assert "client certificate" in rig.log_tail(50)
        cert = tls + [f"--tls-cert={secure['client']}", f"--tls-key={secure['client_key']}"]
        with GatewayRig(secure["address"], kinds=["robotiq-tcp"], name="with-cert", gateway_flags=cert,
                        log_path=tmp_path / "cert.log") as rig:
            rig.wait_for_devices(alice)
            # Commands only from scripters granted the device, each logged with its sender.
            assert alice.send_command("robotiq-tcp", read=True).ok
            with connect(secure, "bob") as bob:
                with expect_error(DENIED, "device_id: 'robotiq-tcp' is not granted to 'bob'"):
                    bob.send_command("robotiq-tcp", read=True)
    log = secure["log"].read_text()
    assert "msg=\"gateway command\"" in log or "gateway command" in log
    assert "by=alice" in log and "by=bob" in log
    assert TOKENS["alice"] not in log and TOKENS["bob"] not in log


@pytest.mark.parametrize("flags,fragment", [
    (["--listen=0.0.0.0:{port}", "--insecure"], "--listen: '0.0.0.0:{port}' is not a loopback address"),
    (["--listen=0.0.0.0:{port}"], "--tls-cert and --tls-key"),
    (["--listen=127.0.0.1:{port}", "--http-listen=0.0.0.0:{port2}", "--insecure"], "--http-listen: '0.0.0.0:{port2}'"),
])
def test_non_loopback_without_tls_refuses_to_start(flags, fragment, tmp_path):
    port, port2 = free_port(), free_port()
    flags = [f.format(port=port, port2=port2) for f in flags]
    if not any(f.startswith("--http-listen") for f in flags):
        flags.append("--http-listen=off")
    result = subprocess.run([str(server_binary()), *flags, *data_dir_flags(tmp_path), "--grasp-data-dir=off"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode != 0
    assert fragment.format(port=port, port2=port2) in result.stderr + result.stdout
    assert "only for 127.0.0.1, ::1 and localhost" in result.stderr + result.stdout


def test_foxglove_live_endpoint_is_loopback_only(tmp_path):
    """The live Foxglove endpoint has neither TLS nor tokens: a wider address stops the start, even with TLS and
    tokens on the other ports."""
    port = free_port()
    result = subprocess.run([str(server_binary()), f"--listen=127.0.0.1:{free_port()}", "--http-listen=off",
                             f"--foxglove-listen=0.0.0.0:{port}", *data_dir_flags(tmp_path), "--grasp-data-dir=off"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode != 0
    assert f"--foxglove-listen: '0.0.0.0:{port}' is not a loopback address" in result.stderr + result.stdout


def test_octave_client_sends_its_token(tmp_path):
    """The Matlab/Octave client's 'Token' option, against a loopback server with tokens on."""
    octave = shutil.which("octave")
    if octave is None:
        pytest.skip("octave not installed (deploy/install-deps.sh installs it)")
    (tmp_path / "tokens").write_text(f"scripter alice {TOKENS['alice']}\nviewer vera {TOKENS['vera']}\n")
    port, http_port = free_port(), free_port()
    with open(tmp_path / "server.log", "wb") as log:
        process = subprocess.Popen([str(server_binary()), f"--listen=127.0.0.1:{port}",
                                    f"--http-listen=127.0.0.1:{http_port}", *data_dir_flags(tmp_path),
                                    "--grasp-data-dir=off", f"--token-file={tmp_path / 'tokens'}"],
                                   stdout=log, stderr=subprocess.STDOUT)
    try:
        script = f"""
addpath('{REPO / 'clients' / 'matlab'}');
url = '127.0.0.1:{http_port}';
for i = 1:100, try, graspsim.Client(url).listMethods(); break; catch, pause(0.1); end, end
alice = graspsim.Client(url, 'Token', '{TOKENS['alice']}');
s = alice.createScene('octave');
printf('created %s\\n', s.id);
try, graspsim.Client(url, 'Token', '{TOKENS['vera']}').createScene('x'); catch e, printf('vera %s\\n', e.identifier); end
try, graspsim.Client(url).listScenes(); catch e, printf('nobody %s\\n', e.identifier); end
"""
        out = subprocess.run([octave, "--no-gui", "--quiet", "--eval", script], capture_output=True, text=True,
                             timeout=300).stdout
        assert "created scene-" in out, out
        assert "vera graspsim:PERMISSION_DENIED" in out, out
        assert "nobody graspsim:UNAUTHENTICATED" in out, out
    finally:
        process.terminate()
        assert process.wait(timeout=30) == 0


def test_owners_shares_and_revocations_survive_a_restart(tmp_path):
    """Scenes persist (--data-dir) and so does who they belong to (auth.sqlite beside them)."""
    (tmp_path / "tokens").write_text(f"admin root {TOKENS['root']}\nscripter alice {TOKENS['alice']}\n"
                                     f"scripter bob {TOKENS['bob']}\n")
    flags = [*data_dir_flags(tmp_path), f"--auth-data-dir={tmp_path / 'auth'}", "--grasp-data-dir=off",
             f"--token-file={tmp_path / 'tokens'}", "--http-listen=off"]

    def start():
        port = free_port()
        process = subprocess.Popen([str(server_binary()), f"--listen=127.0.0.1:{port}", *flags],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return process, f"127.0.0.1:{port}"

    def stop(process):
        process.terminate()
        assert process.wait(timeout=30) == 0

    process, address = start()
    try:
        with graspsim.connect(address, token=TOKENS["alice"], timeout=30) as alice, \
                graspsim.connect(address, token=TOKENS["root"]) as root:
            shared, private = alice.create_scene("shared").id, alice.create_scene("private").id
            alice.share_scene(shared, "bob")
            root.add_token("viewer", "carol", TOKENS["vera"])
            root.revoke_token("bob")
            root.add_token("scripter", "bob", TOKENS["gw"])  # bob's new secret
    finally:
        stop(process)
    assert (tmp_path / "auth" / "auth.sqlite").exists()
    process, address = start()
    try:
        with graspsim.connect(address, token=TOKENS["alice"], timeout=30) as alice, \
                graspsim.connect(address, token=TOKENS["gw"]) as bob, \
                graspsim.connect(address, token=TOKENS["bob"]) as old_bob, \
                graspsim.connect(address, token=TOKENS["vera"]) as carol:
            assert {s.id for s in alice.list_scenes()} >= {shared, private}
            assert bob.get_scene(shared).summary.id == shared
            with expect_error(DENIED, "does not exist or is not yours"):
                bob.get_scene(private)
            with expect_error(UNAUTH):
                old_bob.list_scenes()  # revoked, although the token file still lists the old secret
            assert carol.whoami().role == "viewer"
    finally:
        stop(process)
