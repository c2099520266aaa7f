"""Every code block of README.md, clients/*/README.md and docs/*.md runs against a real server (issue 24), so an
example cannot rot unnoticed. One test per block, id'd doc:line (the line of its opening fence).

By the fence's language tag:
- python: executed in-process, the blocks of one document in one namespace, in document order (a later block may
  use a name an earlier one defined). "127.0.0.1:50051" is replaced with the test server's address.
- sh, bash, shell, console: the lines that call curl or grpcurl run in bash against the test server
  (localhost:8080 / 127.0.0.1:8080 and 127.0.0.1:50051 replaced with its ports); curl gets --fail-with-body, and
  a Server-Sent Events status other than OK fails too. Other lines (make, pip, ninja, starting servers or
  emulators, openssl, test suites ...) build, install or deploy: they are not examples of the API and are not run;
  a block made only of them is reported as skipped, "not run: <programs>". grpcurl lines are skipped when grpcurl
  is not installed (PATH or build/tools/bin).
- matlab, octave: run in one octave-cli session per document (one workspace, document order), against the test
  server's HTTP port ('http://127.0.0.1:8080' replaced); '/path/to/graspsim' and '/path/to/pybullet_data' stand
  for the repository and pybullet's data directory. Octave here has no graphics toolkit, so plotting functions
  are no-ops when none is available.
- Anything else (text, json, yaml, proto, cpp, cmake, ini, dockerfile, no tag: output, listings, source excerpts)
  is not code to run and is not collected.
A block opts out with "# doc-example: skip (reason)" ("% doc-example: ..." in Matlab) as its first line, only where
running is impossible here (real hardware, a cluster, a GPU, the network), always with the reason.
Running one block alone (-k) first runs the earlier blocks of its document it builds on.
"""
import os
import queue
import re
import shlex
import shutil
import subprocess
import threading
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

import pytest

from conftest import REPO_ROOT, ServerProcess, server_binary
# docs/security.md's example is a scripter with a token over TLS: test_security's server (a fixture, module-scoped,
# so an instance of this module's own) stands in for the remote host.
from test_security import TOKENS, secure  # noqa: F401

# docs/benchmarks.md is left out on purpose: its blocks are the shell commands that run the benchmarks
# (tests/bench/run NAME, minutes each), not API examples, and it is edited elsewhere.
DOCS = [REPO_ROOT / "README.md", *sorted(REPO_ROOT.glob("clients/*/README.md")),
        *sorted(p for p in (REPO_ROOT / "docs").glob("*.md") if p.name != "benchmarks.md")]
KINDS = {"python": "python", "py": "python", "sh": "shell", "bash": "shell", "shell": "shell", "console": "shell",
         "matlab": "matlab", "octave": "matlab"}
SKIP_MARKER = re.compile(r"^\s*(?:#|%)\s*doc-example:\s*skip\b\s*(.*)")
BLOCK_TIMEOUT_S = 300


@dataclass(frozen=True)
class Block:
    doc: Path
    line: int      # 1-based line of the opening fence
    kind: str      # python, shell or matlab
    code: str

    @property
    def id(self) -> str:
        return f"{self.doc.relative_to(REPO_ROOT)}:{self.line}"

    def padded(self) -> str:
        """The code after as many newlines as its fence's line number: errors name the document's own lines."""
        return "\n" * self.line + self.code


def blocks_of(doc: Path):
    lines = doc.read_text().splitlines()
    i = 0
    while i < len(lines):
        opening = re.match(r"^(\s*)(`{3,}|~{3,})\s*([\w+-]*)", lines[i])
        i += 1
        if not opening:
            continue
        indent, fence, lang = opening.groups()
        start = i
        while i < len(lines) and not re.match(rf"^\s*{fence[0]}{{{len(fence)},}}\s*$", lines[i]):
            i += 1
        # A block inside a list item is indented with it.
        code = "\n".join(line[len(indent):] if line.startswith(indent) else line for line in lines[start:i]) + "\n"
        i += 1
        if lang.lower() in KINDS:
            yield Block(doc, start, KINDS[lang.lower()], code)


BLOCKS = [block for doc in DOCS for block in blocks_of(doc)]


def substitute(code: str, replacements: dict) -> str:
    for old, new in replacements.items():
        code = code.replace(old, new)
    return code


@pytest.fixture(scope="module")
def doc_server(tmp_path_factory):
    """A server of the examples' own: they create scenes under fixed ids ("web") and leave them behind."""
    proc = ServerProcess([], tmp_path_factory.mktemp("doc-server"))
    yield proc
    code = proc.stop()
    assert code == 0, f"server exited with {code} on SIGTERM:\n{proc.log_tail()}"


class Documents:
    """Per document: its working directory, the blocks already run, the Python namespace, the Octave session."""

    def __init__(self, root: Path):
        self.root = root
        self.ran, self.namespaces, self.octaves = set(), {}, {}

    def workdir(self, doc: Path) -> Path:
        path = self.root / str(doc.relative_to(REPO_ROOT)).replace("/", "_")
        path.mkdir(exist_ok=True)
        return path

    def close(self):
        for octave in self.octaves.values():
            octave.close()


@pytest.fixture(scope="module")
def documents(tmp_path_factory):
    docs = Documents(tmp_path_factory.mktemp("doc-examples"))
    yield docs
    docs.close()


@pytest.mark.parametrize("block", [pytest.param(b, id=b.id) for b in BLOCKS])
def test_doc_example(block, documents, doc_server, request, monkeypatch):
    marker = SKIP_MARKER.match(block.code.splitlines()[0] if block.code.strip() else "")
    if marker:
        pytest.skip(f"marked in the document: {marker.group(1) or 'no reason given'}")
    run = {"python": run_python, "shell": run_shell, "matlab": run_matlab}[block.kind]
    monkeypatch.chdir(documents.workdir(block.doc))
    # graspsim.batch's Ray workers start servers of their own: the binary under test.
    monkeypatch.setenv("GRASPSIM_SERVER", str(server_binary()))
    # The earlier blocks of the document this one may build on, when run alone.
    for earlier in BLOCKS:
        if earlier is block:
            break
        if (earlier.doc, earlier.kind) == (block.doc, block.kind) and block.kind != "shell" \
                and earlier.id not in documents.ran and not SKIP_MARKER.match(earlier.code):
            documents.ran.add(earlier.id)
            run(earlier, documents, doc_server, request)
    documents.ran.add(block.id)
    run(block, documents, doc_server, request)


def run_python(block, documents, server, request):
    replacements = {"127.0.0.1:50051": server.address}
    if block.doc.name == "security.md":
        # The address, alice's token and the CA file of the remote host replaced with test_security's.
        tls = request.getfixturevalue("secure")
        replacements = {"robotpc:50051": tls["address"], "0c8e4f1b7a2d4c9e8f3a6b5d": TOKENS["alice"],
                        '"ca.pem"': repr(str(tls["ca"]))}
    namespace = documents.namespaces.setdefault(block.doc, {"__name__": f"doc_example_{block.doc.stem}"})
    try:
        exec(compile(substitute(block.padded(), replacements), str(block.doc), "exec"), namespace)
    except Exception:  # noqa: BLE001 - the traceback names the document's line; pytest's would print the whole doc
        pytest.fail(f"{block.id} raised:\n{traceback.format_exc()}", pytrace=False)


def shell_lines(code: str):
    """The block's commands: backslash continuations joined, comments, blank lines and here-document bodies
    dropped."""
    lines, heredoc_end = [], None
    for line in code.replace("\\\n", " ").splitlines():
        if heredoc_end is not None:
            heredoc_end = None if line.strip() == heredoc_end else heredoc_end
            continue
        if line.strip() and not line.lstrip().startswith("#"):
            lines.append(line)
            heredoc = re.search(r"<<-?\s*['\"]?(\w+)", line)
            heredoc_end = heredoc.group(1) if heredoc else None
    return lines


def program(line: str) -> str:
    """The program a command line runs ("" for an assignment alone)."""
    try:
        words = shlex.split(line)
    except ValueError:   # an unbalanced quote
        words = line.split()
    words = [w for w in words if not re.match(r"^\w+=", w)]   # VAR=value prefixes
    return os.path.basename(words[0]) if words else ""


def run_shell(block, documents, server, request):
    lines = shell_lines(block.code)
    api = [line for line in lines if program(line) in ("curl", "grpcurl")]
    if not api:
        names = dict.fromkeys(p for p in map(program, lines) if re.fullmatch(r"[\w.+-]+", p))
        pytest.skip(f"not run: {', '.join(names)} (build, install, server, device or file set-up commands, "
                    "not API examples)")
    http = f"127.0.0.1:{server.http_port}"
    grpcurl = shutil.which("grpcurl", path=f"{REPO_ROOT / 'build/tools/bin'}{os.pathsep}{os.environ['PATH']}")
    missing = []
    for line in api:
        line = re.sub(r"\b(localhost|127\.0\.0\.1):8080\b", http, line).replace("127.0.0.1:50051", server.address)
        if program(line) == "grpcurl":
            if not grpcurl:
                missing.append(line)
                continue
            line = re.sub(r"^\s*grpcurl\b", grpcurl, line)
        else:
            line = re.sub(r"^\s*curl\b", "curl --fail-with-body --max-time 60", line)
        done = subprocess.run(["bash", "-c", line], capture_output=True, text=True, timeout=BLOCK_TIMEOUT_S)
        assert done.returncode == 0, f"{line}\nexit code {done.returncode}\n{done.stdout}\n{done.stderr}"
        # A stream's error comes as a Server-Sent Event after HTTP 200.
        refused = re.search(r'event: status\ndata: (\{"code":[1-9].*)', done.stdout)
        assert not refused, f"{line}\n{refused.group(1)}"
    if missing:
        pytest.skip(f"grpcurl not installed (PATH, build/tools/bin): not run: {missing}")


GRAPHICS = ("figure", "plot", "imagesc", "imshow", "axis", "colorbar", "xlabel", "ylabel", "title", "legend",
            "hold", "subplot", "patch", "trisurf", "drawnow")
# The session's loop: sources run_<n>.m files as they appear, in the base workspace, and prints a line when each is
# done. Not commands on stdin: after a pause or a slow webwrite Octave 7 swallows the next line of a piped stdin.
OCTAVE_LOOP = """more off;
if isempty(available_graphics_toolkits())
  warning('off', 'Octave:shadowed-function');
  addpath(fullfile(pwd, 'graphics-stubs'));
end
doc_example_n__ = 0;
while true
  doc_example_n__ = doc_example_n__ + 1;
  while ~exist(sprintf('run_%d.m', doc_example_n__), 'file'), pause(0.02); end
  try
    source(sprintf('run_%d.m', doc_example_n__));
  catch doc_example_err__
    fprintf('@@doc-example-error %s: %s\\n', doc_example_err__.identifier, doc_example_err__.message);
    for k__ = 1:numel(doc_example_err__.stack)
      fprintf('  at %s line %d\\n', doc_example_err__.stack(k__).name, doc_example_err__.stack(k__).line);
    end
  end
  fprintf('@@doc-example-done %d\\n', doc_example_n__); fflush(stdout);
end
"""


class Octave:
    """One octave-cli session per document (one base workspace); blocks run in it one after the other."""

    def __init__(self, cwd: Path):
        octave = shutil.which("octave-cli") or shutil.which("octave")
        if not octave:
            pytest.skip("octave not installed (apt-get install octave)")
        self.cwd, self.count = cwd, 0
        (cwd / "graphics-stubs").mkdir(exist_ok=True)
        for name in GRAPHICS:   # no-ops, used only when Octave has no graphics toolkit (octave-cli, no display)
            (cwd / "graphics-stubs" / f"{name}.m").write_text(f"function varargout = {name}(varargin)\n"
                                                              "  varargout = cell(1, nargout);\nend\n")
        (cwd / "doc_example_loop.m").write_text(OCTAVE_LOOP)
        self.proc = subprocess.Popen([octave, "--no-gui", "--quiet", "--no-window-system", "--norc",
                                      "--eval", "source('doc_example_loop.m')"], cwd=cwd, stdin=subprocess.DEVNULL,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines = queue.Queue()   # a thread reads them: select() would not see lines already buffered
        threading.Thread(target=lambda: [self.lines.put(line) for line in self.proc.stdout] + [self.lines.put(None)],
                         daemon=True).start()

    def run(self, script: Path, timeout: float):
        """(True, output) or (False, output with the error and its stack)."""
        self.count += 1
        staging = self.cwd / "run.tmp"
        staging.write_text(f"source('{script}');\n")
        staging.rename(self.cwd / f"run_{self.count}.m")   # whole, or not there yet, for the loop
        output, deadline = [], time.monotonic() + timeout
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                self.close()
                return False, "".join(output) + f"\n(no answer from Octave within {timeout:g} s)"
            if line is None:
                return False, "".join(output) + f"\n(Octave exited with {self.proc.wait()})"
            if line.strip() == f"@@doc-example-done {self.count}":
                text = "".join(output)
                return "@@doc-example-error" not in text, text
            output.append(line)

    def close(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()


def run_matlab(block, documents, server, request):
    workdir = documents.workdir(block.doc)
    octave = documents.octaves.get(block.doc)
    if octave is None or octave.proc.poll() is not None:
        octave = documents.octaves[block.doc] = Octave(workdir)
    replacements = {"http://127.0.0.1:8080": server.http_url, "/path/to/graspsim": str(REPO_ROOT)}
    if "/path/to/pybullet_data" in block.code:
        replacements["/path/to/pybullet_data"] = pytest.importorskip("pybullet_data").getDataPath()
    code = substitute(block.padded(), replacements)
    script = workdir / f"block_{block.line}.m"
    script.write_text(code)
    ok, output = octave.run(script, timeout=BLOCK_TIMEOUT_S)
    print(output)
    assert ok, f"{block.id} failed in Octave (line numbers are the document's):\n{output}"
