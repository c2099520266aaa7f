#!/usr/bin/env python3
"""Checks every #include of server/src and drivers/ against the folder map of docs/architecture.md (issue 24), and
the server's namespaces against the doc's namespace rule.

The map is the tables of the doc's "Folder map" section, read here, so the doc and the check cannot drift. A row
is "| `folder` | its job | `allowed` `folders` | gRPC / protobuf |"; the last cell allows gRPC headers (grpcpp/,
grpc/, *.grpc.pb.h) when it says grpcpp, and protobuf headers (generated *.pb.h, google/protobuf/) when it says
.pb.h. Fails (exit 1) on an include the map does not allow, a quoted include that names no folder of the map, a
folder the map does not list or a listed one that is gone, and a cycle in the map. Python 3, stdlib only.
"""
import re
import sys
from pathlib import Path

import os

# The repository; a test points it at a small tree of its own (tests/python/test_check_includes.py).
ROOT = Path(os.environ.get("GRASPSIM_CHECK_ROOT", Path(__file__).resolve().parent.parent))
DOC = ROOT / "docs" / "architecture.md"
SOURCES = (".h", ".hpp", ".cpp", ".cc", ".inc")
INCLUDE = re.compile(r'\s*#\s*include\s*([<"])([^>"]+)[>"]')


def folder_of(path: Path):
    """The map's name of a file's folder: "core" for server/src/core/..., "drivers/can" for drivers/can/..."""
    parts = path.relative_to(ROOT).parts
    if parts[:2] == ("server", "src"):
        return parts[2] if len(parts) > 3 else "server/src"  # a file directly in server/src is in no folder
    return "/".join(parts[:2]) if len(parts) > 2 else "drivers"


def read_map():
    """folder -> (allowed folders, gRPC allowed, protobuf allowed, line of the doc)."""
    rules, section = {}, False
    for number, line in enumerate(DOC.read_text().splitlines(), 1):
        if line.startswith("## "):
            section = line.strip() == "## Folder map"
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if section and line.startswith("| `") and len(cells) == 4:
            name = cells[0].strip("`")
            rules[name] = (set(re.findall(r"`([^`]+)`", cells[2])), "grpcpp" in cells[3], ".pb.h" in cells[3], number)
    return rules


def target_of(include: str, quoted: bool, folders):
    """What an include names: ("folder", name), ("grpc", None), ("protobuf", None) or None (a library's header)."""
    parts = include.split("/")
    if parts[0] == "drivers" and len(parts) > 2:
        return "folder", "drivers/" + parts[1]
    if parts[0] in folders and len(parts) > 1:
        return "folder", parts[0]
    if parts[0] in ("grpcpp", "grpc") or include.endswith(".grpc.pb.h"):  # *.grpc.pb.h includes grpcpp itself
        return "grpc", None
    if include.endswith(".pb.h") or parts[0] == "google":
        return "protobuf", None
    # Quoted includes are the project's: one that names no folder ("../core/x.h", "x.h") would escape the map.
    return ("unknown", None) if quoted else None


def find_cycle(rules):
    state = {}  # folder -> 1 while on the path, 2 when done

    def visit(folder, path):
        state[folder] = 1
        for other in sorted(rules[folder][0] & rules.keys()):
            if state.get(other) == 1:
                return path[path.index(other):] + [other]
            if other not in state and (cycle := visit(other, path + [other])):
                return cycle
        state[folder] = 2
        return None

    for folder in sorted(rules):
        if folder not in state and (cycle := visit(folder, [folder])):
            return cycle
    return None


NAMESPACE = re.compile(r"\s*namespace\s+([\w:]+)\s*\{")
TYPE = re.compile(r"(?:struct|class|enum class|enum)\s+(\w+)(?:\s+final)?\s*(?::[^:]|\{|$)|using\s+(\w+)\s*=")


def check_namespaces(folders):
    """The namespace rule of docs/architecture.md: graspsim::<folder> is declared only in that folder, and a type
    declared at namespace scope in a header has a name no other namespace of the server declares."""
    failures, types = [], {}
    for path in sorted((ROOT / "server" / "src").rglob("*")):
        if path.suffix not in SOURCES or len(path.relative_to(ROOT).parts) < 4:
            continue
        folder, namespace = folder_of(path), None
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if match := NAMESPACE.match(line):
                namespace = match.group(1)
                parts = namespace.split("::")
                if parts[0] == "graspsim" and len(parts) > 1 and parts[1] in folders and parts[1] != folder:
                    failures.append(f"{path.relative_to(ROOT)}:{number}: namespace {namespace} belongs to "
                                    f"{parts[1]}/, not {folder}/ [docs/architecture.md, Namespaces]")
            elif path.suffix == ".h" and namespace and (match := TYPE.match(line)) and \
                    (match.group(2) or not line.rstrip().endswith(";")):  # a forward declaration declares nothing
                name = match.group(1) or match.group(2)
                types.setdefault(name, {}).setdefault(namespace, f"{path.relative_to(ROOT)}:{number}")
    for name, where in sorted(types.items()):
        if len({n for n in where if n.startswith("graspsim")}) > 1:
            failures.append(f"type {name} is declared in {len(where)} namespaces ({', '.join(sorted(where.values()))}):"
                            f" give each its own name [docs/architecture.md, Namespaces]")
    return failures


def main():
    rules = read_map()
    failures, passed, files = [], 0, 0
    where = f"{DOC.relative_to(ROOT)}, Folder map"
    if not rules:
        sys.exit(f"check-includes: no folder map found in {where}")
    present = {p.name for p in (ROOT / "server" / "src").iterdir() if p.is_dir()}
    present |= {"drivers/" + p.name for p in (ROOT / "drivers").iterdir() if p.is_dir()}
    for folder in sorted(present - rules.keys()):
        failures.append(f"{folder}: folder not in the map ({where}): add its row")
    for folder in sorted(rules.keys() - present):
        failures.append(f"{DOC.relative_to(ROOT)}:{rules[folder][3]}: {folder} is in the map but not in the tree")
    if cycle := find_cycle(rules):
        failures.append(f"{where}: cycle {' -> '.join(cycle)}: folders may not include each other in a circle")

    used, known = set(), rules.keys() | present
    for top in (ROOT / "server" / "src", ROOT / "drivers"):
        for path in sorted(p for p in top.rglob("*") if p.suffix in SOURCES):
            files += 1
            folder = folder_of(path)
            allowed, grpc_ok, protobuf_ok, _ = rules.get(folder, (set(), False, False, 0))
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                match = INCLUDE.match(line)
                if not match:
                    continue
                quoted, include = match.group(1) == '"', match.group(2)
                target = target_of(include, quoted, known)
                if target is None:
                    continue  # a system or third-party library's header: not the map's business
                kind, name = target
                broken = None
                if kind == "folder" and name != folder and name not in allowed:
                    broken = f"{folder} may not include {name} (allowed: {', '.join(sorted(allowed)) or 'none'})"
                elif kind == "grpc" and not grpc_ok:
                    broken = f"{folder} may not include gRPC headers (grpcpp/, grpc/, *.grpc.pb.h)"
                elif kind == "protobuf" and not protobuf_ok:
                    broken = f"{folder} may not include protobuf headers (*.pb.h, google/protobuf/)"
                elif kind == "unknown":
                    broken = "a quoted include must start with a folder of the map (\"core/error.h\")"
                if broken:
                    failures.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}: {broken} [{where}]")
                else:
                    passed += 1
                    if kind == "folder" and name != folder:
                        used.add((folder, name))

    failures += check_namespaces(present)
    for failure in failures:
        print(failure)
    # Allowed but unused edges do not fail: they are a hint that the map can be tightened.
    unused = sorted(f"{f} -> {o}" for f, (allowed, *_) in rules.items() for o in allowed if (f, o) not in used)
    if unused:
        print(f"check-includes: note: allowed in the map but included nowhere: {', '.join(unused)}")
    print(f"check-includes: {passed} passed, {len(failures)} failed (the includes of project folders and of gRPC and "
          f"protobuf headers in {files} files of {len(present)} folders, against {where}; and the namespace rule)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
