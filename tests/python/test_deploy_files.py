"""Offline checks of deploy/ (issue 23): what can be validated without a cluster, a registry or a container runtime.

- Kubernetes: every object `kustomize build` renders for base/ and each overlay, and the RayJob, is walked against
  the `kubernetes` package's models (every key a known field, every value of the field's type, required fields
  present); the RayJob (a CRD) gets its own field check and its pod templates the core models. Cross-references:
  selectors, volume mounts, Secrets/ConfigMaps, ports, probes, and the Envoy config in the ConfigMap (ring hash on
  graspsim-scene-id, one endpoint per StatefulSet replica, round robin without the header, mounted file paths).
  kustomize comes from the Go module proxy into build/tools/bin (like ghz in tests/bench/run).
- systemd: `systemd-analyze verify` of the gateway unit (ExecStart pointed at build/bin) says nothing about it,
  `systemd-analyze security --offline` rates it at most MAX_EXPOSURE, and the real graspsim-gateway sends READY=1
  and WATCHDOG=1 to a $NOTIFY_SOCKET bound here, as the unit's Type=notify and WatchdogSec= expect.
- Dockerfile and compose.yaml: parsed; bases, stages, user, copied files (present, not dockerignored), the
  runtime libraries against the binaries' NEEDED entries, and every flag given to a binary against its --help.
"""
from __future__ import annotations

import fnmatch
import json
import os
import re
import shutil
import socket
import subprocess
import time
from pathlib import Path
from typing import Any, Dict, List

import pytest
import yaml

REPO = Path(__file__).resolve().parents[2]
DEPLOY = REPO / "deploy"
K8S = DEPLOY / "k8s"
BIN = REPO / "build" / "bin"
TOOLS = REPO / "build" / "tools"
KUSTOMIZE_VERSION = "v5.5.0"  # builds with Go >= 1.22
# Envoy's API as Go types, of the Envoy release the Deployment runs (envoyproxy/envoy:v1.32.x).
ENVOY_API = {"github.com/envoyproxy/go-control-plane/envoy": "v1.32.4", "sigs.k8s.io/yaml": "v1.4.0"}
# systemd-analyze security's overall exposure (0 = locked down, 10 = none): the unit is at 1.9; above 2.0 systemd
# rates it MEDIUM. One directive dropped moves it by 0.1-0.4, so the main ones are also checked by name.
MAX_EXPOSURE = 2.0
SCENE_HEADER = "graspsim-scene-id"


# ------------------------------------------------------------------------------------------------ helpers

def binary(name: str) -> Path:
    path = BIN / name
    if not path.exists():
        pytest.skip(f"{path} is not built (make build)")
    return path


_HELP: Dict[str, str] = {}


def help_text(name: str) -> str:
    """The binary's usage text (its flags), from --help or a bare call."""
    if name not in _HELP:
        path = binary(name)
        args = [] if name == "graspsim-emulator" else ["--help"]
        done = subprocess.run([str(path), *args], capture_output=True, text=True, timeout=30)
        _HELP[name] = done.stdout + done.stderr
    return _HELP[name]


def check_flags(name: str, args: List[str], where: str) -> None:
    """Every --flag in args is one the binary's usage names."""
    usage = help_text(name)
    for arg in args:
        if arg.startswith("--"):
            flag = arg.split("=", 1)[0]
            assert re.search(re.escape(flag) + r"(?![\w-])", usage), \
                f"{where}: {name} has no flag {flag} (its usage: {usage[:2000]})"


def cmake_executables() -> set:
    names = set()
    # Not the build trees (build, build-fuzz): gigabytes, and nothing of theirs is a source.
    tops = [p for p in REPO.iterdir() if p.is_dir() and not p.name.startswith(("build", "."))]
    for path in [REPO / "CMakeLists.txt"] + [f for top in tops for f in top.rglob("CMakeLists.txt")]:
        names.update(re.findall(r"add_executable\(\s*([\w.-]+)", path.read_text()))
    return names


# ------------------------------------------------------------------------------------------------ kustomize

def go_binary() -> str:
    go = shutil.which("go") or "/usr/local/go/bin/go"
    if not os.access(go, os.X_OK):
        pytest.skip("rendering deploy/k8s needs kustomize, installed with Go (>= 1.22), which is not installed")
    return go


@pytest.fixture(scope="session")
def kustomize() -> Path:
    path = TOOLS / "bin" / "kustomize"
    if path.exists():
        version = subprocess.run([str(path), "version"], capture_output=True, text=True).stdout
        if KUSTOMIZE_VERSION in version:
            return path
    env = dict(os.environ, GOBIN=str(TOOLS / "bin"), GOPATH=str(TOOLS / "go"), GOFLAGS="-modcacherw")
    done = subprocess.run([go_binary(), "install", f"sigs.k8s.io/kustomize/kustomize/v5@{KUSTOMIZE_VERSION}"],
                          env=env, capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, f"installing kustomize {KUSTOMIZE_VERSION} failed:\n{done.stderr[-3000:]}"
    return path


ENVOY_CHECK_GO = r"""// Checks an Envoy bootstrap file as Envoy parses it: YAML -> JSON -> the v3 Bootstrap message, unknown fields and
// bad enum values refused, then every message (typed_config Any's unpacked) against Envoy's validation rules.
package main

import (
	"fmt"
	"os"

	bootstrap "github.com/envoyproxy/go-control-plane/envoy/config/bootstrap/v3"
	_ "github.com/envoyproxy/go-control-plane/envoy/extensions/filters/http/health_check/v3"
	_ "github.com/envoyproxy/go-control-plane/envoy/extensions/filters/http/router/v3"
	_ "github.com/envoyproxy/go-control-plane/envoy/extensions/filters/network/http_connection_manager/v3"
	_ "github.com/envoyproxy/go-control-plane/envoy/extensions/transport_sockets/tls/v3"
	_ "github.com/envoyproxy/go-control-plane/envoy/extensions/upstreams/http/v3"
	"google.golang.org/protobuf/encoding/protojson"
	"google.golang.org/protobuf/proto"
	"google.golang.org/protobuf/reflect/protoreflect"
	"google.golang.org/protobuf/types/known/anypb"
	"sigs.k8s.io/yaml"
)

type validator interface{ ValidateAll() error }

// check validates m and every message below it, unpacking Any fields (PGV does not look inside them).
func check(m protoreflect.Message, path string) error {
	if v, ok := m.Interface().(validator); ok {
		if err := v.ValidateAll(); err != nil {
			return fmt.Errorf("%s: %w", path, err)
		}
	}
	if any, ok := m.Interface().(*anypb.Any); ok {
		inner, err := any.UnmarshalNew()
		if err != nil {
			return fmt.Errorf("%s: %w", path, err)
		}
		return check(inner.ProtoReflect(), path+"("+any.TypeUrl+")")
	}
	var err error
	m.Range(func(fd protoreflect.FieldDescriptor, v protoreflect.Value) bool {
		if fd.Message() == nil || fd.IsMap() {
			return true
		}
		if fd.IsList() {
			for i := 0; i < v.List().Len() && err == nil; i++ {
				err = check(v.List().Get(i).Message(), fmt.Sprintf("%s.%s[%d]", path, fd.Name(), i))
			}
		} else {
			err = check(v.Message(), path+"."+string(fd.Name()))
		}
		return err == nil
	})
	return err
}

func main() {
	data, err := os.ReadFile(os.Args[1])
	if err == nil {
		var json []byte
		if json, err = yaml.YAMLToJSON(data); err == nil {
			var config bootstrap.Bootstrap
			if err = protojson.Unmarshal(json, &config); err == nil {
				err = check(proto.Message(&config).ProtoReflect(), "bootstrap")
			}
		}
	}
	if err != nil {
		fmt.Fprintf(os.Stderr, "%s: %v\n", os.Args[1], err)
		os.Exit(1)
	}
	fmt.Println("ok")
}
"""


@pytest.fixture(scope="session")
def envoy_check() -> Path:
    """A checker of Envoy config files built from Envoy's API (go-control-plane): strict protojson parsing of the
    bootstrap, then Envoy's validation rules on every message. Built once into build/tools/bin."""
    go = go_binary()
    source = TOOLS / "envoy-check"
    source.mkdir(parents=True, exist_ok=True)
    if not (source / "main.go").exists() or (source / "main.go").read_text() != ENVOY_CHECK_GO:
        (source / "main.go").write_text(ENVOY_CHECK_GO)
    env = dict(os.environ, GOPATH=str(TOOLS / "go"), GOCACHE=str(TOOLS / "go-cache"), GOFLAGS="-modcacherw")
    steps = [[go, "build", "-o", str(TOOLS / "bin" / "graspsim-envoy-check"), "."]]
    if not (source / "go.mod").exists():
        steps = [[go, "mod", "init", "graspsim-envoy-check"],
                 [go, "get", *(f"{m}@{v}" for m, v in ENVOY_API.items())], [go, "mod", "tidy"]] + steps
    for step in steps:
        done = subprocess.run(step, cwd=source, env=env, capture_output=True, text=True, timeout=1200)
        assert done.returncode == 0, f"{' '.join(step)}:\n{done.stderr[-3000:]}"
    return TOOLS / "bin" / "graspsim-envoy-check"


def kustomizations() -> List[Path]:
    dirs = [K8S / "base"] + sorted(p for p in (K8S / "overlays").iterdir() if (p / "kustomization.yaml").exists())
    assert len(dirs) >= 2, "deploy/k8s has no overlays"
    return dirs


def render(kustomize: Path, directory: Path) -> List[dict]:
    done = subprocess.run([str(kustomize), "build", str(directory)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, f"kustomize build {directory.relative_to(REPO)}:\n{done.stderr}"
    objects = [o for o in yaml.safe_load_all(done.stdout) if o]
    assert objects, f"kustomize build {directory} rendered nothing"
    return objects


# ------------------------------------------------------------------------------------------------ schema walk

def k8s_models():
    return pytest.importorskip("kubernetes.client", reason="pip install 'clients/python[test]' (kubernetes)")


# apiVersion, kind -> model class. A kind not here (and not a CRD below) fails: nothing passes unchecked.
MODELS = {
    ("v1", "Namespace"): "V1Namespace",
    ("v1", "Service"): "V1Service",
    ("v1", "ConfigMap"): "V1ConfigMap",
    ("v1", "Secret"): "V1Secret",
    ("v1", "ServiceAccount"): "V1ServiceAccount",
    ("v1", "PersistentVolumeClaim"): "V1PersistentVolumeClaim",
    ("apps/v1", "StatefulSet"): "V1StatefulSet",
    ("apps/v1", "Deployment"): "V1Deployment",
    ("policy/v1", "PodDisruptionBudget"): "V1PodDisruptionBudget",
    ("networking.k8s.io/v1", "NetworkPolicy"): "V1NetworkPolicy",
    ("batch/v1", "Job"): "V1Job",
}
QUANTITY_MAPS = {"requests", "limits", "capacity", "hard"}  # Quantity: a string, or a JSON number


def walk(value: Any, type_name: str, path: str, errors: List[str]) -> None:
    """Checks `value` (parsed YAML) against a kubernetes.client type name ('V1PodSpec', 'List[V1Volume]', 'str')."""
    models = k8s_models()
    if type_name.startswith("List["):
        if not isinstance(value, list):
            errors.append(f"{path}: expected a list, got {type(value).__name__}")
            return
        for i, item in enumerate(value):
            walk(item, type_name[5:-1], f"{path}[{i}]", errors)
        return
    if type_name.startswith("Dict["):
        if not isinstance(value, dict):
            errors.append(f"{path}: expected a map, got {type(value).__name__}")
            return
        inner = type_name[5:-1].split(", ", 1)[1]
        quantity = path.rsplit(".", 1)[-1] in QUANTITY_MAPS
        for key, item in value.items():
            if not isinstance(key, str):
                errors.append(f"{path}: key {key!r} is not a string")
            if quantity and isinstance(item, (int, float)) and not isinstance(item, bool):
                continue
            walk(item, inner, f"{path}.{key}", errors)
        return
    primitive = {"str": (str,), "bytes": (str,), "datetime": (str,), "date": (str,), "int": (int,),
                 "float": (int, float), "bool": (bool,)}
    if type_name == "object":
        return  # IntOrString, RawExtension: any
    if type_name in primitive:
        ok = isinstance(value, primitive[type_name]) and not (type_name in ("int", "float") and isinstance(value, bool))
        if not ok:
            errors.append(f"{path}: expected {type_name}, got {type(value).__name__} {value!r}")
        return
    cls = getattr(models, type_name, None)
    if cls is None:
        errors.append(f"{path}: the kubernetes package has no model {type_name}")
        return
    if not isinstance(value, dict):
        errors.append(f"{path}: expected a {type_name} map, got {type(value).__name__}")
        return
    by_json = {json_name: attr for attr, json_name in cls.attribute_map.items()}
    for key, item in value.items():
        attr = by_json.get(key)
        if attr is None:
            errors.append(f"{path}.{key}: not a field of {type_name} (fields: {sorted(by_json)})")
            continue
        walk(item, cls.openapi_types[attr], f"{path}.{key}", errors)
    for attr, field in getattr(cls, "model_fields", {}).items():  # pydantic models (kubernetes >= 35) know these
        json_name = cls.attribute_map.get(attr, attr)
        if field.is_required() and json_name not in value and json_name not in ("apiVersion", "kind"):
            errors.append(f"{path}: {type_name} requires {json_name}")


def validate_object(obj: dict, where: str) -> None:
    api, kind = obj.get("apiVersion"), obj.get("kind")
    name = f"{where}: {kind} {obj.get('metadata', {}).get('name')}"
    model = MODELS.get((api, kind))
    assert model, f"{name}: no schema known for {api} {kind}: add it to MODELS or a CRD check"
    errors: List[str] = []
    walk(obj, model, kind, errors)
    assert not errors, f"{name} does not validate:\n  " + "\n  ".join(errors)


def test_schema_walk_rejects_what_the_api_server_would():
    """The walk itself: an unknown field, a wrong type and a missing required field are each reported."""
    good = {"apiVersion": "v1", "kind": "Service", "metadata": {"name": "s"},
            "spec": {"ports": [{"port": 80, "targetPort": "http"}], "selector": {"a": "b"}}}
    validate_object(good, "test")
    for bad, words in [
        ({"spec": {"ports": [{"port": 80, "targtPort": "http"}]}}, "targtPort: not a field"),
        ({"spec": {"ports": [{"port": "80"}]}}, "expected int"),
        ({"spec": {"ports": [{"targetPort": 80}]}}, "requires port"),
        ({"metadata": {"name": "s", "labels": {"on": True}}}, "expected str"),
    ]:
        errors: List[str] = []
        walk({**good, **bad}, "V1Service", "Service", errors)
        assert any(words in e for e in errors), (bad, errors)


# ------------------------------------------------------------------------------------------------ kubernetes

@pytest.fixture(scope="session")
def rendered(kustomize) -> Dict[str, List[dict]]:
    return {str(d.relative_to(K8S)): render(kustomize, d) for d in kustomizations()}


def by_kind(objects: List[dict], kind: str) -> List[dict]:
    return [o for o in objects if o["kind"] == kind]


def one(objects: List[dict], kind: str, name: str = None) -> dict:
    found = [o for o in by_kind(objects, kind) if name is None or o["metadata"]["name"] == name]
    assert len(found) == 1, f"expected one {kind} {name or ''}, found {len(found)}"
    return found[0]


def test_every_rendered_object_validates_against_the_kubernetes_schemas(rendered):
    for where, objects in rendered.items():
        for obj in objects:
            validate_object(obj, where)


def test_statefulset_keeps_one_store_per_replica_and_is_locked_down(rendered):
    for where, objects in rendered.items():
        sts = one(objects, "StatefulSet", "graspsim")
        spec = sts["spec"]
        assert spec["replicas"] == 3, where
        pod = spec["template"]["spec"]
        labels = spec["template"]["metadata"]["labels"]
        assert all(labels.get(k) == v for k, v in spec["selector"]["matchLabels"].items()), where
        headless = one(objects, "Service", spec["serviceName"])
        assert headless["spec"].get("clusterIP") == "None", f"{where}: {spec['serviceName']} is not headless"
        claims = {t["metadata"]["name"] for t in spec["volumeClaimTemplates"]}
        volumes = {v["name"]: v for v in pod.get("volumes", [])}
        (server,) = [c for c in pod["containers"] if c["name"] == "server"]
        mounts = {m["mountPath"]: m for m in server["volumeMounts"]}
        for mount in server["volumeMounts"]:
            assert mount["name"] in volumes or mount["name"] in claims, f"{where}: volume {mount['name']} undeclared"
        assert mounts["/var/lib/graspsim"]["name"] in claims, f"{where}: --data-dir is not on a claim template"
        assert pod["securityContext"]["runAsNonRoot"] is True and pod["securityContext"]["runAsUser"] == 10001
        sc = server["securityContext"]
        assert sc["readOnlyRootFilesystem"] is True and sc["allowPrivilegeEscalation"] is False
        assert sc["capabilities"]["drop"] == ["ALL"]
        for probe in ("readinessProbe", "livenessProbe"):
            assert server[probe]["grpc"]["port"] == 50051, f"{where}: {probe} is not gRPC health on 50051"
        assert server["resources"]["requests"]["cpu"] and server["resources"]["requests"]["memory"]
        # The server reads these paths; each must be inside a mount of the right Secret.
        args = server.get("args", [])
        check_flags("graspsim-server", args, f"{where} StatefulSet args")
        for flag in ("--tls-cert", "--tls-key", "--token-file"):
            (value,) = [a.split("=", 1)[1] for a in args if a.startswith(flag + "=")]
            assert any(value == p or value.startswith(p.rstrip("/") + "/") for p in mounts), f"{where}: {value}"
        secrets = {v["secret"]["secretName"] for v in volumes.values() if "secret" in v}
        assert {"graspsim-tls", "graspsim-tokens"} <= secrets, where


def test_resource_requests_hold_the_measured_memory_of_a_full_replica():
    """The memory request holds an idle replica plus --max-scenes (256) work-cycle scenes, as measured by
    tests/bench/run fleet and written in docs/scaling.md; the limit is at least the request."""
    doc = (REPO / "docs" / "scaling.md").read_text()
    idle = float(re.search(r"memory of an idle replica \| ([\d.]+) MiB", doc).group(1))
    per_scene = float(re.search(r"work cycle's kind[^|]*\| ([\d.]+) MiB", doc).group(1))
    resources = yaml.safe_load((K8S / "base" / "statefulset.yaml").read_text())["spec"]["template"]["spec"][
        "containers"][0]["resources"]
    mib = lambda q: float(q[:-2]) * (1024 if q.endswith("Gi") else 1) if q[-2:] in ("Mi", "Gi") else float(q) / 2**20
    request, limit = mib(resources["requests"]["memory"]), mib(resources["limits"]["memory"])
    assert request >= idle + 256 * per_scene, f"request {request} MiB < {idle} + 256 x {per_scene} MiB"
    assert limit >= request


def test_services_select_pods_and_name_their_ports(rendered):
    for where, objects in rendered.items():
        pods = [w["spec"]["template"] for w in by_kind(objects, "StatefulSet") + by_kind(objects, "Deployment")]
        for svc in by_kind(objects, "Service"):
            selector = svc["spec"]["selector"]
            targets = [p for p in pods if all(p["metadata"]["labels"].get(k) == v for k, v in selector.items())]
            assert len(targets) == 1, f"{where}: Service {svc['metadata']['name']} selects {len(targets)} workloads"
            ports = {p["name"]: p["containerPort"] for c in targets[0]["spec"]["containers"] for p in c.get("ports", [])}
            for port in svc["spec"]["ports"]:
                target = port.get("targetPort", port["port"])
                assert target in ports or target in ports.values(), \
                    f"{where}: Service {svc['metadata']['name']} port {port['name']} -> {target}: no such container port"
        for pdb in by_kind(objects, "PodDisruptionBudget") + by_kind(objects, "NetworkPolicy"):
            selector = (pdb["spec"].get("selector") or pdb["spec"]["podSelector"])["matchLabels"]
            assert any(all(p["metadata"]["labels"].get(k) == v for k, v in selector.items()) for p in pods), \
                f"{where}: {pdb['kind']} {pdb['metadata']['name']} selects no pods"


def envoy_config(objects: List[dict]) -> dict:
    deployment = one(objects, "Deployment", "graspsim-envoy")
    pod = deployment["spec"]["template"]["spec"]
    (maps,) = [v["configMap"]["name"] for v in pod["volumes"] if "configMap" in v]
    config_map = one(objects, "ConfigMap", maps)  # the generated (hash-suffixed) name must resolve
    return yaml.safe_load(config_map["data"]["envoy.yaml"])


def test_envoy_hashes_scenes_by_header_and_balances_the_rest(rendered):
    for where, objects in rendered.items():
        config = envoy_config(objects)
        replicas = one(objects, "StatefulSet", "graspsim")["spec"]["replicas"]
        headless = one(objects, "StatefulSet", "graspsim")["spec"]["serviceName"]
        clusters = {c["name"]: c for c in config["static_resources"]["clusters"]}
        listeners = {l["name"]: l for l in config["static_resources"]["listeners"]}
        grpc = listeners["grpc"]
        assert grpc["address"]["socket_address"]["port_value"] == 50051
        hcm = grpc["filter_chains"][0]["filters"][0]["typed_config"]
        assert "http2_protocol_options" in hcm or hcm.get("codec_type") == "HTTP2"
        routes = [r for vh in hcm["route_config"]["virtual_hosts"] for r in vh["routes"]]
        for route in routes:
            assert route["route"]["cluster"] in clusters, f"{where}: route to unknown cluster {route['route']}"
        hashed = [r for r in routes if any(h.get("header", {}).get("header_name") == SCENE_HEADER
                                           for h in r["route"].get("hash_policy", []))]
        assert hashed, f"{where}: no route hashes on {SCENE_HEADER}"
        (scene_route,) = hashed
        assert {"name": SCENE_HEADER, "present_match": True} in scene_route["match"]["headers"]
        scenes = clusters[scene_route["route"]["cluster"]]
        assert scenes["lb_policy"] == "RING_HASH" and scenes["type"] == "STRICT_DNS"
        assert scenes["common_lb_config"]["consistent_hashing_lb_config"]["use_hostname_for_hashing"] is True
        hosts = [e["endpoint"]["address"]["socket_address"]["address"]
                 for group in scenes["load_assignment"]["endpoints"] for e in group["lb_endpoints"]]
        assert hosts == [f"graspsim-{i}.{headless}" for i in range(replicas)], \
            f"{where}: the ring lists {hosts}, the StatefulSet has {replicas} replicas"
        # After the hashed route, calls without the header are balanced per call.
        fallback = routes[routes.index(scene_route) + 1:]
        assert fallback and fallback[-1]["match"] == {"prefix": "/"} and "headers" not in fallback[-1]["match"]
        assert clusters[fallback[-1]["route"]["cluster"]]["lb_policy"] == "ROUND_ROBIN"
        for name in {r["route"]["cluster"] for r in routes}:
            cluster = clusters[name]
            http2 = cluster["typed_extension_protocol_options"]["envoy.extensions.upstreams.http.v3.HttpProtocolOptions"]
            assert "http2_protocol_options" in http2["explicit_http_config"], f"{where}: {name} is not HTTP/2"
            if name != "graspsim_hub":
                assert any("grpc_health_check" in h for h in cluster["health_checks"]), f"{where}: {name}"
            for group in cluster["load_assignment"]["endpoints"]:
                for e in group["lb_endpoints"]:
                    host = e["endpoint"]["address"]["socket_address"]["address"]
                    assert host == headless or host.endswith("." + headless), f"{where}: {name} -> {host}"


def test_envoy_accepts_its_config(rendered, envoy_check, tmp_path):
    """What Envoy's own parser would refuse: unknown fields, bad enums, unknown typed_config types, values outside
    Envoy's validation rules (ports, empty names, ...)."""
    configs = {yaml.safe_dump(envoy_config(objects)) for objects in rendered.values()}
    for i, text in enumerate(sorted(configs)):
        path = tmp_path / f"envoy-{i}.yaml"
        path.write_text(text)
        done = subprocess.run([str(envoy_check), str(path)], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("RING_HASH", "RINGHASH", 1))
    assert subprocess.run([str(envoy_check), str(bad)], capture_output=True).returncode != 0


def test_envoy_files_ports_and_types_match_its_deployment(rendered):
    known_types = {
        "type.googleapis.com/envoy.extensions.filters.network.http_connection_manager.v3.HttpConnectionManager",
        "type.googleapis.com/envoy.extensions.filters.http.router.v3.Router",
        "type.googleapis.com/envoy.extensions.filters.http.health_check.v3.HealthCheck",
        "type.googleapis.com/envoy.extensions.transport_sockets.tls.v3.DownstreamTlsContext",
        "type.googleapis.com/envoy.extensions.transport_sockets.tls.v3.UpstreamTlsContext",
        "type.googleapis.com/envoy.extensions.upstreams.http.v3.HttpProtocolOptions",
    }
    for where, objects in rendered.items():
        config = envoy_config(objects)
        pod = one(objects, "Deployment", "graspsim-envoy")["spec"]["template"]["spec"]
        (envoy,) = pod["containers"]
        mounts = [m["mountPath"] for m in envoy["volumeMounts"]]
        config_arg = envoy["args"][envoy["args"].index("-c") + 1]
        assert any(config_arg.startswith(m + "/") for m in mounts), f"{where}: {config_arg} is not mounted"
        text = json.dumps(config)
        for path in re.findall(r'"filename": "([^"]+)"', text):
            assert any(path.startswith(m + "/") for m in mounts), f"{where}: envoy reads {path}, not mounted"
        for type_url in re.findall(r'"@type": "([^"]+)"', text):
            assert type_url in known_types, f"{where}: unexpected Envoy type {type_url}"
        ports = {p["containerPort"] for p in envoy["ports"]}
        for listener in config["static_resources"]["listeners"]:
            assert listener["address"]["socket_address"]["port_value"] in ports, f"{where}: {listener['name']}"
        assert config["admin"]["address"]["socket_address"]["address"] == "127.0.0.1", "admin must stay local"


RAYJOB_SPEC = {"activeDeadlineSeconds", "backoffLimit", "rayClusterSpec", "submitterPodTemplate", "metadata",
               "clusterSelector", "submitterConfig", "managedBy", "deletionStrategy", "entrypoint", "runtimeEnvYAML",
               "jobId", "submissionMode", "entrypointResources", "entrypointNumCpus", "entrypointNumGpus",
               "ttlSecondsAfterFinished", "shutdownAfterJobFinishes", "suspend", "schedule"}
RAYCLUSTER_SPEC = {"headGroupSpec", "workerGroupSpecs", "rayVersion", "enableInTreeAutoscaling",
                   "autoscalerOptions", "headServiceAnnotations", "suspend", "managedBy", "gcsFaultToleranceOptions",
                   "upgradeStrategy", "authOptions"}
HEAD_GROUP = {"serviceType", "headService", "enableIngress", "rayStartParams", "template", "resources", "labels"}
WORKER_GROUP = {"groupName", "replicas", "minReplicas", "maxReplicas", "numOfHosts", "rayStartParams", "template",
                "scaleStrategy", "suspend", "idleTimeoutSeconds", "resources", "labels"}


def test_rayjob_has_the_fields_kuberay_needs():
    """RayJob is a CRD (no model in the kubernetes package): its own fields by hand (KubeRay's ray.io/v1 types),
    its pod templates against the core models."""
    docs = [d for d in yaml.safe_load_all((K8S / "ray" / "rayjob.yaml").read_text()) if d]
    (job,) = docs
    assert job["apiVersion"] == "ray.io/v1" and job["kind"] == "RayJob" and job["metadata"]["name"]
    spec = job["spec"]
    assert set(spec) <= RAYJOB_SPEC, f"RayJob spec: unknown fields {set(spec) - RAYJOB_SPEC}"
    assert isinstance(spec["entrypoint"], str) and "graspsim.batch" in spec["entrypoint"]
    yaml.safe_load(spec.get("runtimeEnvYAML", "{}"))
    cluster = spec["rayClusterSpec"]
    assert set(cluster) <= RAYCLUSTER_SPEC, f"rayClusterSpec: unknown fields {set(cluster) - RAYCLUSTER_SPEC}"
    head = cluster["headGroupSpec"]
    assert set(head) <= HEAD_GROUP and "template" in head
    templates = {"headGroupSpec": head["template"]}
    for params in [head.get("rayStartParams", {})] + [w.get("rayStartParams", {}) for w in cluster["workerGroupSpecs"]]:
        assert all(isinstance(v, str) for v in params.values()), f"rayStartParams must be strings: {params}"
    for worker in cluster["workerGroupSpecs"]:
        assert set(worker) <= WORKER_GROUP, f"worker group: unknown fields {set(worker) - WORKER_GROUP}"
        assert worker["groupName"] and "template" in worker
        assert worker["minReplicas"] <= worker.get("replicas", worker["minReplicas"]) <= worker["maxReplicas"]
        templates[worker["groupName"]] = worker["template"]
    if "submitterPodTemplate" in spec:
        templates["submitterPodTemplate"] = spec["submitterPodTemplate"]
    for name, template in templates.items():
        errors: List[str] = []
        walk(template, "V1PodTemplateSpec", f"RayJob.{name}", errors)
        assert not errors, "\n".join(errors)
    # The entrypoint's flags are graspsim.batch's (its argparse, read without importing Ray).
    batch_main = (REPO / "clients/python/src/graspsim/batch/__main__.py").read_text()
    for flag in re.findall(r"(--[\w-]+)", spec["entrypoint"]):
        assert f'"{flag}"' in batch_main, f"python -m graspsim.batch has no {flag}"


# ------------------------------------------------------------------------------------------------ systemd

UNIT = DEPLOY / "systemd" / "graspsim-gateway.service"


@pytest.fixture
def unit_with_built_binary(tmp_path) -> Path:
    if shutil.which("systemd-analyze") is None:
        pytest.skip("systemd-analyze is not installed")
    text = UNIT.read_text().replace("/opt/graspsim/bin/graspsim-gateway", str(binary("graspsim-gateway")))
    path = tmp_path / UNIT.name
    path.write_text(text)
    return path


def test_gateway_unit_verifies(unit_with_built_binary):
    done = subprocess.run(["systemd-analyze", "verify", str(unit_with_built_binary)],
                          capture_output=True, text=True, timeout=60)
    # Only what it says about this unit: other units of the machine are not ours to judge.
    ours = [l for l in (done.stdout + done.stderr).splitlines() if UNIT.name in l or UNIT.stem in l]
    assert done.returncode == 0 and not ours, done.stdout + done.stderr


def test_gateway_unit_is_hardened(unit_with_built_binary):
    done = subprocess.run(["systemd-analyze", "security", "--offline=true", "--no-pager",
                           f"--threshold={int(MAX_EXPOSURE * 10)}", str(unit_with_built_binary)],
                          capture_output=True, text=True, timeout=60)
    level = re.search(r"Overall exposure level for \S+: ([\d.]+)", done.stdout)
    assert level, done.stdout + done.stderr
    assert done.returncode == 0 and float(level.group(1)) <= MAX_EXPOSURE, \
        f"exposure {level.group(1)} > {MAX_EXPOSURE}:\n" + "\n".join(l for l in done.stdout.splitlines() if "✗" in l)


def unit_settings() -> Dict[str, List[str]]:
    settings: Dict[str, List[str]] = {}
    for line in UNIT.read_text().splitlines():
        if "=" in line and not line.lstrip().startswith(("#", "[")):
            key, value = line.split("=", 1)
            settings.setdefault(key.strip(), []).append(value.strip())
    return settings


def test_gateway_unit_watchdog_and_flags():
    s = unit_settings()
    assert s["Type"] == ["notify"] and s["Restart"] == ["on-failure"] and s["WatchdogSec"]
    assert s["CapabilityBoundingSet"] == [""] and s["NoNewPrivileges"] == ["yes"]
    for key, value in [("ProtectSystem", "strict"), ("ProtectHome", "yes"), ("PrivateTmp", "yes"),
                       ("DynamicUser", "yes"), ("DevicePolicy", "closed"), ("SystemCallFilter", "@system-service"),
                       ("SystemCallArchitectures", "native"), ("MemoryDenyWriteExecute", "yes")]:
        assert value in s.get(key, []), f"{key}={value} is gone from the unit"
    assert any(d.startswith("char-ttyUSB") for d in s["DeviceAllow"]), "no DeviceAllow for the RTU adapter"
    families = s["RestrictAddressFamilies"][0].split()
    assert {"AF_UNIX", "AF_INET", "AF_INET6", "AF_CAN"} <= set(families)
    assert s["EnvironmentFile"] == ["/etc/graspsim/gateway.env"]
    exec_start = s["ExecStart"][0].split()
    assert exec_start[0] == "/opt/graspsim/bin/graspsim-gateway"
    check_flags("graspsim-gateway", exec_start[1:], "ExecStart")
    credentials = {c.split(":", 1)[0] for c in s.get("LoadCredential", [])}
    for arg in exec_start[1:]:
        if "%d/" in arg:
            assert arg.split("%d/", 1)[1] in credentials, f"{arg}: no LoadCredential of that name"


def test_gateway_speaks_sd_notify(tmp_path):
    """The real graspsim-gateway under a stand-in for systemd: READY=1 once its device is initialised, then
    WATCHDOG=1 at half of $WATCHDOG_USEC (server unreachable: reconnecting is not a reason to stop pinging)."""
    emulator = subprocess.Popen([str(binary("graspsim-emulator")), "robotiq-tcp", "--port=0"],
                                stdout=subprocess.PIPE, text=True)
    gateway = None
    notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    try:
        port = emulator.stdout.readline().split()[1].rsplit(":", 1)[1]
        name = f"graspsim-test-notify-{os.getpid()}"
        notify.bind("\0" + name)  # the abstract namespace, as systemd's own socket may be
        notify.settimeout(10)
        env = dict(os.environ, NOTIFY_SOCKET="@" + name, WATCHDOG_USEC="400000")
        env.pop("WATCHDOG_PID", None)
        gateway = subprocess.Popen([str(binary("graspsim-gateway")), "--server=127.0.0.1:1",
                                    f"--device=robotiq-tcp:127.0.0.1:{port}"], env=env,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        assert notify.recv(4096) == b"READY=1"
        times = []
        deadline = time.monotonic() + 1.5
        while time.monotonic() < deadline:
            message = notify.recv(4096)
            times.append(time.monotonic())
            assert message == b"WATCHDOG=1"
        assert len(times) >= 4, f"{len(times)} pings in 1.5 s at WATCHDOG_USEC=400000"
        gaps = [b - a for a, b in zip(times[1:], times[2:])]  # the first ping follows READY at once
        assert min(gaps) > 0.15 and max(gaps) < 0.4, f"pings every {gaps} s, expected 0.2"
    finally:
        notify.close()
        for process in (gateway, emulator):
            if process is not None:
                process.terminate()
                process.wait(timeout=20)
    assert gateway.returncode == 0, gateway.stderr.read()


def syscall_group(group: str) -> set:
    listing = subprocess.run(["systemd-analyze", "syscall-filter", group], capture_output=True, text=True).stdout
    names = set()
    for line in listing.splitlines()[1:]:
        line = line.strip()
        if line and not line.startswith("#"):
            names |= syscall_group(line) if line.startswith("@") else {line}
    return names


def test_gateway_syscalls_pass_the_units_filters(tmp_path):
    """graspsim-gateway connecting, registering, polling, pinging and stopping (strace) makes only the system calls
    and opens only the socket families the unit allows: SystemCallFilter and RestrictAddressFamilies would
    otherwise kill it under systemd, which this machine does not run as PID 1."""
    if shutil.which("strace") is None or shutil.which("systemd-analyze") is None:
        pytest.skip("needs strace and systemd-analyze")
    settings = unit_settings()
    allowed, denied = set(), set()
    for value in settings["SystemCallFilter"]:
        for group in value.lstrip("~").split():
            (denied if value.startswith("~") else allowed).update(syscall_group(group) if group.startswith("@")
                                                                    else {group})
    families = set(settings["RestrictAddressFamilies"][0].split())
    emulator = subprocess.Popen([str(binary("graspsim-emulator")), "robotiq-tcp", "--port=0"],
                                stdout=subprocess.PIPE, text=True)
    server = subprocess.Popen([str(binary("graspsim-server")), "--listen=127.0.0.1:0", "--http-listen=off",
                               "--data-dir=off"], stderr=subprocess.PIPE, text=True)
    gateway = None
    trace = tmp_path / "gateway.strace"
    try:
        device_port = emulator.stdout.readline().split()[1].rsplit(":", 1)[1]
        server_port = None
        while server_port is None:
            line = server.stderr.readline()
            assert line, "the server exited"
            found = re.search(r"msg=listening .*port=(\d+)", line)
            server_port = found and found.group(1)
        env = dict(os.environ, NOTIFY_SOCKET="@graspsim-test-none", WATCHDOG_USEC="400000")
        gateway = subprocess.Popen(["strace", "-f", "-qq", "-o", str(trace), str(binary("graspsim-gateway")),
                                    f"--server=127.0.0.1:{server_port}", f"--device=robotiq-tcp:127.0.0.1:{device_port}"],
                                   env=env, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            line = gateway.stderr.readline()
            assert line, "the gateway exited before it connected"
            if "msg=connected" in line:
                break
        time.sleep(0.5)  # polls and watchdog pings
        children = subprocess.run(["pgrep", "-P", str(gateway.pid)], capture_output=True, text=True).stdout.split()
        for child in children:
            os.kill(int(child), 15)
        assert gateway.wait(timeout=20) == 0
    finally:
        for process in (gateway, server, emulator):
            if process is not None and process.poll() is None:
                process.terminate()
                process.wait(timeout=20)
    text = trace.read_text()
    calls = set(re.findall(r"^\d+\s+(?:<\.\.\. )?(\w+)[( ]", text, re.M)) - {"execve", "resumed"}  # exec: strace's
    assert {"connect", "sendto", "epoll_wait"} <= calls, f"the trace looks incomplete: {sorted(calls)}"
    assert not calls - allowed, f"not in SystemCallFilter: {sorted(calls - allowed)}"
    assert not calls & denied, f"denied by SystemCallFilter=~: {sorted(calls & denied)}"
    used = set(re.findall(r"socket\((AF_\w+)", text))
    assert used and used <= families, f"socket families {sorted(used)}, the unit allows {sorted(families)}"


# ------------------------------------------------------------------------------------------------ container

DOCKERFILE = DEPLOY / "container" / "Dockerfile"


def dockerfile_instructions() -> List[dict]:
    parse = pytest.importorskip("dockerfile_parse", reason="pip install 'clients/python[test]' (dockerfile-parse)")
    structure = parse.DockerfileParser(path=str(DOCKERFILE), cache_content=False).structure
    return [i for i in structure if i["instruction"] != "COMMENT"]


def stages() -> List[List[dict]]:
    result: List[List[dict]] = []
    for instruction in dockerfile_instructions():
        if instruction["instruction"] == "FROM":
            result.append([])
        if result:
            result[-1].append(instruction)
        else:
            assert instruction["instruction"] in ("ARG",), f"{instruction} before the first FROM"
    return result


def dockerignored(relative: str) -> bool:
    patterns = [l.strip() for l in (REPO / ".dockerignore").read_text().splitlines()
                if l.strip() and not l.startswith("#")] if (REPO / ".dockerignore").exists() else []
    parts = relative.split("/")
    prefixes = ["/".join(parts[:i]) for i in range(1, len(parts) + 1)]
    return any(fnmatch.fnmatch(p, pat) or fnmatch.fnmatch(p, pat.replace("**/", "")) for p in prefixes for pat in patterns)


def json_args(value: str) -> List[str]:
    args = json.loads(value)
    assert isinstance(args, list) and all(isinstance(a, str) for a in args), f"not JSON exec form: {value}"
    return args


def test_dockerfile_builds_in_stages_and_runs_as_a_user():
    all_stages = stages()
    assert len(all_stages) >= 2, "not a multi-stage build"
    for stage in all_stages:
        base = stage[0]["value"].split()[0]
        assert re.fullmatch(r"debian:bookworm(-slim)?(@sha256:[0-9a-f]{64})?", base), f"FROM {base}: not Debian 12"
    final = all_stages[-1]
    users = [i["value"] for i in final if i["instruction"] == "USER"]
    assert users and users[-1].split(":")[0] not in ("root", "0"), "the final stage runs as root"
    uid = users[-1].split(":")[0]
    assert any(f"--uid {uid}" in i["value"] for i in final if i["instruction"] == "RUN"), f"uid {uid} not created"
    values = {i["instruction"]: i["value"] for i in final}
    assert set(values["EXPOSE"].split()) == {"50051", "8080"}
    assert "/var/lib/graspsim" in values["VOLUME"]


def test_dockerfile_copies_what_exists_and_builds_what_it_runs():
    executables = cmake_executables()
    copied_binaries = set()
    build_commands = " ".join(i["value"] for s in stages()[:-1] for i in s if i["instruction"] == "RUN")
    for stage in stages():
        for instruction in stage:
            if instruction["instruction"] not in ("COPY", "ADD"):
                continue
            words = instruction["value"].split()
            flags = [w for w in words if w.startswith("--")]
            sources = [w for w in words if not w.startswith("--")][:-1]
            if any(f.startswith("--from=") for f in flags):
                for source in sources:
                    if "/build/bin/" in source:
                        copied_binaries.add(source.rsplit("/", 1)[1])
                continue
            for source in sources:
                assert (REPO / source).exists(), f"COPY {source}: not in the repository"
                assert not dockerignored(source), f"COPY {source}: excluded by .dockerignore"
    for name in copied_binaries:
        assert name in executables, f"{name} is copied but no CMakeLists.txt builds it"
        assert name in build_commands, f"{name} is copied but the build stage does not build it"
    entrypoint = json_args([i["value"] for i in stages()[-1] if i["instruction"] == "ENTRYPOINT"][-1])
    command = json_args([i["value"] for i in stages()[-1] if i["instruction"] == "CMD"][-1])
    program = entrypoint[0]
    assert program.startswith("/opt/graspsim/bin/") and Path(program).name in copied_binaries
    assert Path(program).name in executables
    for flag in ("--listen=0.0.0.0:50051", "--http-listen=0.0.0.0:8080", "--data-dir=/var/lib/graspsim"):
        assert flag in entrypoint
    # Serving every interface needs TLS (and tokens): the default command gives both.
    assert {a.split("=")[0] for a in command} >= {"--tls-cert", "--tls-key", "--token-file"}
    check_flags("graspsim-server", entrypoint[1:] + command, "Dockerfile ENTRYPOINT/CMD")
    assert (REPO / ".dockerignore").exists() and dockerignored("build/bin/graspsim-server")


def test_runtime_stage_installs_every_library_the_binaries_link():
    if shutil.which("dpkg") is None or shutil.which("readelf") is None:
        pytest.skip("needs dpkg and readelf (Debian) to map libraries to packages")
    runtime = " ".join(i["value"] for i in stages()[-1] if i["instruction"] == "RUN")
    installed = set(re.findall(r"(?<![\w.+-])([a-z0-9][a-z0-9.+-]+)(?![\w.+-])", runtime))
    in_slim = {"libc6", "libgcc-s1", "libstdc++6"}  # debian:bookworm-slim has these (apt needs them)
    missing = {}
    for name in ("graspsim-server", "graspsim-gateway", "graspsim-emulator", "graspsim-mesh-import"):
        path = binary(name)
        needed = re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]",
                            subprocess.run(["readelf", "-d", str(path)], capture_output=True, text=True).stdout)
        resolved = dict(re.findall(r"^\s*(\S+) => (\S+)", subprocess.run(["ldd", str(path)], capture_output=True,
                                                                           text=True).stdout, re.M))
        for library in needed:
            file = resolved.get(library)
            assert file, f"{name}: {library} not found by ldd"
            owner = subprocess.run(["dpkg", "-S", os.path.realpath(file)], capture_output=True, text=True)
            if owner.returncode != 0:
                owner = subprocess.run(["dpkg", "-S", file], capture_output=True, text=True)
            package = owner.stdout.split(":", 1)[0].strip()
            assert package, f"{name}: no Debian package owns {file}"
            if package not in installed and package not in in_slim:
                missing.setdefault(package, []).append(f"{name}: {library}")
    assert not missing, f"the runtime stage does not install: {missing}"


# ------------------------------------------------------------------------------------------------ compose

COMPOSE = DEPLOY / "compose.yaml"


def test_compose_services_references_and_flags():
    compose = yaml.safe_load(COMPOSE.read_text())
    services = compose["services"]
    declared_volumes = set(compose.get("volumes") or {})
    declared_secrets = compose.get("secrets") or {}
    dockerfile_binaries = {Path(w).name for s in stages() for i in s if i["instruction"] == "COPY"
                           for w in i["value"].split() if "/build/bin/" in w}
    ports: Dict[str, str] = {}
    for name, service in services.items():
        assert "image" in service or "build" in service, f"{name}: neither image nor build"
        if "build" in service:
            context = (COMPOSE.parent / service["build"]["context"]).resolve()
            assert (context / service["build"]["dockerfile"]).resolve() == DOCKERFILE.resolve(), name
        for volume in service.get("volumes", []):
            source = volume.split(":", 1)[0] if isinstance(volume, str) else volume["source"]
            assert source.startswith((".", "/")) or source in declared_volumes, f"{name}: volume {source} undeclared"
        mounted = set()
        for secret in service.get("secrets", []):
            source = secret if isinstance(secret, str) else secret["source"]
            assert source in declared_secrets, f"{name}: secret {source} undeclared"
            target = f"/run/secrets/{source}" if isinstance(secret, str) else secret.get("target", source)
            mounted.add(target if target.startswith("/") else f"/run/secrets/{target}")
        mode = service.get("network_mode", "")
        if mode.startswith("service:"):
            assert mode.split(":", 1)[1] in services, f"{name}: network_mode {mode}"
        for other in service.get("depends_on", []):
            assert other in services, f"{name}: depends_on {other}"
        program = service.get("entrypoint", ["/opt/graspsim/bin/graspsim-server"])
        args = list(program[1:]) + list(service.get("command", []))
        binary_name = Path(program[0]).name
        assert program[0] == f"/opt/graspsim/bin/{binary_name}" and binary_name in dockerfile_binaries, name
        if binary_name == "graspsim-emulator":
            check_flags(binary_name, args[1:], f"compose {name}")
            ports[name] = [a.split("=")[1] for a in args if a.startswith("--port=")][0]
        else:
            check_flags(binary_name, args, f"compose {name}")
        for arg in args:  # a file a flag names is a mounted secret (or the data dir)
            value = arg.split("=", 1)[1] if "=" in arg else ""
            if value.startswith(("/etc/", "/run/secrets/")):
                assert value in mounted, f"{name}: {arg} names a file no secret mounts"
    for secret in declared_secrets.values():
        path = (COMPOSE.parent / secret["file"]).resolve()
        assert dockerignored(str(path.relative_to(REPO))), f"{secret['file']}: secrets must stay out of the image"
    gateway = services["gateway"]["entrypoint"]
    device = [a for a in gateway if a.startswith("--device=")][0]
    emulator = services["gateway"]["network_mode"].split(":", 1)[1]
    assert device.endswith(f":127.0.0.1:{ports[emulator]}"), f"{device}: not the emulator's port {ports[emulator]}"
    server = [a.split("=", 1)[1] for a in gateway if a.startswith("--server=")][0]
    assert server.split(":")[0] in services and server.endswith(":50051")


def test_compose_config_when_docker_compose_is_here():
    docker = shutil.which("docker")
    if docker is None or subprocess.run([docker, "compose", "version"], capture_output=True).returncode != 0:
        pytest.skip("docker compose is not installed (the structural checks above still ran)")
    done = subprocess.run([docker, "compose", "-f", str(COMPOSE), "config", "--no-interpolate", "--quiet"],
                          capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, COMPOSE_PROJECT_NAME="graspsim-test"))
    # Missing secret files are the operator's to make; anything else is ours.
    problems = [l for l in done.stderr.splitlines() if "secrets" not in l or "not found" not in l]
    assert done.returncode == 0 or not problems, done.stderr
