"""Robot files from the local disk: the format of a URDF, MJCF or SDF file, and every file it needs uploaded.

add_robot(path=...) reads the file, finds the mesh files its collision geometry names (URDF <collision> meshes,
MJCF <asset><mesh file> under <compiler meshdir/assetdir> and its <include>d files, SDF <collision> mesh <uri>s
and <include>d models), resolves them on this machine (package://, model://, file:// and relative paths) and
uploads each under the path the server looks it up by (docs/import.md):

    package://pkg/a/b.stl -> a/b.stl      model://m/a/b.stl -> m/a/b.stl      file:///x/b.stl -> b.stl
    meshes/../b.stl -> b.stl              ../meshes/b.stl -> meshes/b.stl     (MJCF) meshdir/file, likewise

i.e. the reference without its scheme (and package name), lexically normalised, with leading "./" and "../"
dropped; an absolute path is uploaded by its base name, which the server tries last. Nothing is sent when a
referenced file is missing on disk: MissingFilesError lists every one of them.
"""
from __future__ import annotations

import os
import posixpath
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Dict, Iterable, List, Mapping, Optional, Sequence, Set, Tuple, Union

from graspsim._scene import FileInfo
from graspsim._upload import digest

if TYPE_CHECKING:
    from graspsim._client import Client

FilePath = Union[str, os.PathLike[str]]
PackageRoots = Union[None, Mapping[str, Union[str, os.PathLike[str]]], Sequence[Union[str, os.PathLike[str]]]]

FORMATS = ("urdf", "mjcf", "sdf")
_EXTENSIONS = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".sdf": "sdf", ".world": "sdf"}
_ROOT_TAGS = {"robot": "urdf", "mujoco": "mjcf", "sdf": "sdf"}
MAX_UPLOAD_PATH = 256  # characters, the server's limit (server/src/core/validate.cpp CheckRelativePath)


class MissingFilesError(FileNotFoundError):
    """Files a robot file references that are not on this machine; .missing: [(reference, where it was
    looked for, the file that references it)]. Raised before anything is sent to the server."""

    def __init__(self, source: Path, missing: List[Tuple[str, str, str]]):
        self.source = source
        self.missing = missing
        lines = [f"  {ref!r} (in {where}): looked for {tried}" for ref, tried, where in missing]
        super().__init__(f"{source}: {len(missing)} referenced file(s) not found on disk:\n" + "\n".join(lines))


@dataclass
class RobotFiles:
    """What add_robot(path=...) sends: the file's text and format, and the local files to upload
    ({path in the scene: local path}) in the order they were first referenced."""
    path: Path
    format: str
    text: str
    files: Dict[str, Path] = field(default_factory=dict)


def detect_format(path: Path, text: str) -> str:
    """"urdf", "mjcf" or "sdf": from the extension (.urdf; .xml/.mjcf; .sdf/.world), else the root element."""
    by_extension = _EXTENSIONS.get(path.suffix.lower())
    if by_extension:
        return by_extension
    try:
        tag = ET.fromstring(text).tag
    except ET.ParseError as err:
        raise ValueError(f"{path}: not an XML robot file ({err})") from None
    if tag not in _ROOT_TAGS:
        raise ValueError(f"{path}: root element <{tag}> is none of <robot> (URDF), <mujoco> (MJCF), <sdf> (SDF)")
    return _ROOT_TAGS[tag]


def scene_path(reference: str) -> str:
    """The path under which the server looks a mesh reference up among a scene's files (module docstring)."""
    stripped = reference.strip()
    if stripped.startswith("package://"):
        rest = stripped[len("package://"):]
        stripped = rest.split("/", 1)[1] if "/" in rest else rest
    elif stripped.startswith("model://"):
        stripped = stripped[len("model://"):]
    elif stripped.startswith("file://"):
        stripped = stripped[len("file://"):]
    return normalise(stripped)


def normalise(path: str) -> str:
    """posixpath.normpath without leading "./" and "../" components; an absolute path becomes its base name."""
    if posixpath.isabs(path):
        return posixpath.basename(posixpath.normpath(path))
    parts = posixpath.normpath(path).split("/")
    while parts and parts[0] in (".", ".."):
        parts.pop(0)
    return "/".join(parts)


class _Resolver:
    """Finds referenced files on disk; records the missing ones instead of failing at the first."""

    def __init__(self, source: Path, package_roots: PackageRoots):
        self.source = source
        self.base = source.parent
        if package_roots is None:
            self.named: Dict[str, Path] = {}
            self.roots = [self.base, *self.base.parents]
            self.default_roots = True
        elif isinstance(package_roots, Mapping):
            self.named = {str(k): Path(v).expanduser().resolve() for k, v in package_roots.items()}
            self.roots = []
            self.default_roots = False
        elif isinstance(package_roots, (str, os.PathLike)):
            self.named, self.roots, self.default_roots = {}, [Path(package_roots).expanduser().resolve()], False
        else:
            self.named = {}
            self.roots = [Path(r).expanduser().resolve() for r in package_roots]
            self.default_roots = False
        self.files: Dict[str, Path] = {}
        self.missing: List[Tuple[str, str, str]] = []

    def _package_dir(self, package: str) -> Tuple[Optional[Path], str]:
        """The directory of a ROS package / Gazebo model name, and a description of where it was looked for."""
        if package in self.named:
            return self.named[package], f"package_roots[{package!r}] = {self.named[package]}"
        for root in self.roots:
            if (root / package).is_dir():
                return root / package, ""
            if root.name == package:  # the file lies inside the package: .../pkg/urdf/robot.urdf
                return root, ""
        where = "the file's directory and its parents" if self.default_roots else \
            f"package_roots {[str(r) for r in self.roots] or list(self.named)}"
        return None, f"a directory {package!r} in {where}"

    def local(self, reference: str, base: Path) -> Tuple[Optional[Path], str]:
        """(local path or None, where it was looked for) of a reference made by a file in directory base."""
        ref = reference.strip()
        for scheme in ("package://", "model://"):
            if ref.startswith(scheme):
                package, _, rest = ref[len(scheme):].partition("/")
                directory, tried = self._package_dir(package)
                if directory is None:
                    return None, tried
                candidate = directory / rest
                return (candidate if candidate.is_file() else None), str(candidate)
        if ref.startswith("file://"):
            ref = ref[len("file://"):]
        elif "://" in ref:
            return None, f"a local file (the scheme {ref.split('://')[0]}:// is not supported)"
        candidate = Path(ref) if os.path.isabs(ref) else base / ref
        if not candidate.is_file() and os.path.isabs(ref):  # as PyBullet does: "/meshes/a.stl" next to the file
            beside = base / ref.lstrip("/")
            if beside.is_file():
                return beside, str(beside)
            return None, f"{candidate} or {beside}"
        return (candidate if candidate.is_file() else None), str(candidate)

    def add(self, reference: str, base: Path, where: Path, key: Optional[str] = None) -> Optional[Path]:
        """Resolves a reference and records it for upload under key (default: scene_path(reference))."""
        found, tried = self.local(reference, base)
        if found is None:
            self.missing.append((reference, tried, str(where)))
            return None
        key = key if key is not None else scene_path(reference)
        if not key or len(key) > MAX_UPLOAD_PATH:
            raise ValueError(f"{where}: {reference!r} maps to the scene path {key!r}, which the server cannot "
                             f"take (empty or longer than {MAX_UPLOAD_PATH} characters)")
        earlier = self.files.get(key)
        if earlier is not None and earlier.resolve() != found.resolve() and digest(earlier)[1] != digest(found)[1]:
            raise ValueError(f"{where}: {reference!r} ({found}) and {earlier} both map to the scene path {key!r} "
                             f"but differ; the server would use one for both")
        self.files.setdefault(key, found)
        return found

    def result(self, fmt: str, text: str) -> RobotFiles:
        if self.missing:
            raise MissingFilesError(self.source, self.missing)
        return RobotFiles(self.source, fmt, text, dict(self.files))


def _parse(path: Path, text: str) -> ET.Element:
    """The root element; as lenient as the TinyXML that PyBullet and MuJoCo read with: blank lines before the
    XML declaration and anything after the root element's end are ignored here (the server gets the text as is)."""
    try:
        return ET.fromstring(text)
    except ET.ParseError as err:
        first = err
    trimmed = text.lstrip()
    match = re.match(r"(?:<\?xml[^>]*\?>\s*)?(?:<!--.*?-->\s*)*<([A-Za-z_][\w.-]*)", trimmed, re.S)
    if match:
        end = trimmed.rfind(f"</{match.group(1)}>")
        if end >= 0:
            trimmed = trimmed[:end + len(match.group(1)) + 3]
    try:
        return ET.fromstring(trimmed)
    except ET.ParseError:
        raise ValueError(f"{path}: XML error: {first}") from None


def _urdf(resolver: _Resolver, root: ET.Element) -> None:
    for mesh in root.iterfind("./link/collision/geometry/mesh"):
        filename = mesh.get("filename")
        if filename:
            resolver.add(filename, resolver.base, resolver.source)


def _mjcf(resolver: _Resolver, root: ET.Element) -> None:
    """Meshes of <asset> in the file and its includes; MuJoCo resolves include files and meshdir against the
    main file's directory. The included files themselves are uploaded too (the server reads them)."""
    documents: List[Tuple[Path, ET.Element]] = [(resolver.source, root)]
    seen = {resolver.source.resolve()}
    index = 0
    while index < len(documents):  # breadth-first over <include file>, each file once
        where, element = documents[index]
        index += 1
        for include in element.iter("include"):
            name = include.get("file")
            if not name:
                continue
            found = resolver.add(name, resolver.base, where, key=normalise(name))
            if found is None and not os.path.isabs(name):  # nested includes relative to their own file
                resolver.missing.pop()
                found = resolver.add(name, where.parent, where, key=normalise(name))
            if found is not None and found.resolve() not in seen:
                seen.add(found.resolve())
                documents.append((found, _parse(found, found.read_text(encoding="utf-8", errors="replace"))))
    meshdir = ""
    for _, element in documents:
        for compiler in element.iter("compiler"):
            value = compiler.get("meshdir", compiler.get("assetdir"))
            if value is not None:
                meshdir = value
    for where, element in documents:
        for asset in element.iter("asset"):
            for mesh in asset.iter("mesh"):
                name = mesh.get("file")
                if name:
                    joined = posixpath.join(meshdir, name) if meshdir else name
                    resolver.add(joined, resolver.base, where, key=normalise(joined))


def _sdf(resolver: _Resolver, root: ET.Element, base: Path, where: Path, prefix: str, seen: Set[Path]) -> None:
    """<collision> meshes, and <include>d models (model://name resolved under the package roots; the model's
    file and its meshes uploaded under "name/...")."""
    for collision in root.iter("collision"):
        for uri_element in collision.iterfind("./geometry/mesh/uri"):
            if uri_element.text and uri_element.text.strip():
                ref = uri_element.text.strip()
                key = scene_path(ref) if "://" in ref or os.path.isabs(ref) else normalise(posixpath.join(prefix, ref))
                resolver.add(ref, base, where, key=key)
    for include in root.iter("include"):
        uri = include.findtext("uri")
        if not uri or not uri.strip():
            continue
        uri = uri.strip()
        directory, tried = _include_target(resolver, uri, base)
        if directory is None:
            resolver.missing.append((uri, tried, str(where)))
            continue
        model_file = directory if directory.is_file() else _model_sdf(directory)
        if model_file is None:
            resolver.missing.append((uri, f"model.config or model.sdf in {directory}", str(where)))
            continue
        model_prefix = scene_path(uri) if "://" in uri else normalise(posixpath.join(prefix, uri))
        if directory.is_file():
            model_prefix = posixpath.dirname(model_prefix)
        if model_file.resolve() in seen:
            continue
        seen.add(model_file.resolve())
        resolver.add(str(model_file), base, where, key=normalise(posixpath.join(model_prefix, model_file.name)))
        config = model_file.parent / "model.config"
        if config.is_file():
            resolver.add(str(config), base, where, key=normalise(posixpath.join(model_prefix, "model.config")))
        text = model_file.read_text(encoding="utf-8", errors="replace")
        _sdf(resolver, _parse(model_file, text), model_file.parent, model_file, model_prefix, seen)


def _include_target(resolver: _Resolver, uri: str, base: Path) -> Tuple[Optional[Path], str]:
    """The model directory (or SDF file) an SDF <include><uri> names, and where it was looked for."""
    if uri.startswith("model://"):
        name, _, rest = uri[len("model://"):].partition("/")
        directory, tried = resolver._package_dir(name)
        if directory is None:
            return None, tried
        target = directory / rest if rest else directory
    elif "://" in uri and not uri.startswith("file://"):
        return None, f"a local model (the scheme {uri.split('://')[0]}:// is not supported)"
    else:
        local = uri[len("file://"):] if uri.startswith("file://") else uri
        target = Path(local) if os.path.isabs(local) else base / local
    return (target if target.exists() else None), str(target)


def _model_sdf(directory: Path) -> Optional[Path]:
    """A Gazebo model directory's SDF file: the one model.config names (the last <sdf>, the newest), else
    model.sdf."""
    config = directory / "model.config"
    if config.is_file():
        try:
            names = [e.text.strip() for e in ET.parse(config).getroot().iter("sdf") if e.text and e.text.strip()]
        except ET.ParseError:
            names = []
        for name in reversed(names):
            if (directory / name).is_file():
                return directory / name
    return directory / "model.sdf" if (directory / "model.sdf").is_file() else None


def collect(path: Union[str, os.PathLike[str]], package_roots: PackageRoots = None,
            fmt: Optional[str] = None) -> RobotFiles:
    """Reads a robot file and resolves every file it needs on the server (module docstring).

    package_roots: {package: directory}, or directories that hold package (or Gazebo model) directories;
    None = the file's directory and its parents (where ROS packages and Gazebo models usually sit).
    Raises FileNotFoundError for the file itself, MissingFilesError listing every missing referenced file,
    ValueError for a file that is not XML or not one of the three formats.
    """
    source = Path(path).expanduser().resolve()
    text = source.read_text(encoding="utf-8")
    fmt = fmt or detect_format(source, text)
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {', '.join(FORMATS)}, got {fmt!r}")
    root = _parse(source, text)
    resolver = _Resolver(source, package_roots)
    if fmt == "urdf":
        _urdf(resolver, root)
    elif fmt == "mjcf":
        _mjcf(resolver, root)
    else:
        _sdf(resolver, root, resolver.base, source, "", {source})
    return resolver.result(fmt, text)


def upload_missing(client: Client, scene_id: str, files: Mapping[str, Path],
                   present: Optional[Iterable[FileInfo]] = None) -> List[str]:
    """Uploads each file the scene does not already hold with the same SHA-256; returns the uploaded paths.
    present: the scene's FileInfo list if the caller has it (else get_scene is asked)."""
    if not files:
        return []
    if present is None:
        present = client.get_scene(scene_id).files
    held = {info.path: info.sha256 for info in present}
    uploaded = []
    for scene_file, local in files.items():
        if held.get(scene_file) == digest(local)[1]:
            continue
        client.upload_file(scene_id, scene_file, local)
        uploaded.append(scene_file)
    return uploaded
