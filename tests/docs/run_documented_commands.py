#!/usr/bin/python3
"""Runs the shell commands of the documentation, so that a documented command cannot rot (#19).

usage: run_documented_commands.py [--repo DIR] [--build DIR] [--slow] [--list] [--only TEXT]
                                  [--timeout S] [--keep] [--jobs N]

Where the commands are: every fenced block whose info string is `sh`, `bash`, `shell` or
`console` in README.md, docs/**/*.md and examples/*/README.md. Blocks of other languages (yaml,
cpp, text) and blocks without a language are not commands: label a block `sh` to have it run.

What a command is: the lines of a block, in order; blank lines and lines that are only a `#`
comment are left out, a trailing `# comment` stays (bash ignores it). A line ending in `\\`
continues on the next, and so does a line that leaves a compound command open (`for … do`
until `done`, an open quote): lines are joined until `bash -n` accepts them. In a block with
`$ ` prompts (a transcript) only the prompted lines (and their continuations) are commands; the
other lines are output and are not compared.

Markers (an HTML comment, invisible on GitHub, alone on the last non-blank line before the
block's opening fence; the reason in parentheses is required):
    <!-- doc-test: skip (reason) -->   never run here (setup that installs packages and rebuilds,
                                        builds of other presets, hour-long fuzzing, …)
    <!-- doc-test: slow (reason) -->   run only with --slow (on demand; budget of the quick set
                                        in ctest: about a minute on two cores)
A marker applies to the whole block: a block mixing quick and slow commands is split in two.
Setup is skipped, not mapped: the two commands at the top of README.md run scripts/setup.sh
(packages, a rebuild of build/) and then the main example or the whole suite, of which this test
is a part; the test runs on the build that exists (--build), and the examples' own READMEs run
their models. The fuzzing block (another build, build-fuzz/, and an hour) is skipped as well.
`paraview FILE …` (an interactive viewer) is never started: the check is that FILE exists when
the commands before it have run.

Where they run: each Markdown file gets its own scratch folder, a fresh copy of the repository's
files (those `git ls-files` lists, tracked or not ignored, as they are in the working tree)
with `build` a symbolic link to the build folder (--build), so `./build/isoflex`, `tools/…` and
`examples/…` resolve as in the repository and nothing is written into it. The file's commands
run in order from the scratch folder's root (later ones read what earlier ones wrote under
out/), each by `bash -e -c`, with MPLBACKEND=Agg. A command fails the test if it exits non-zero
or runs out of time (--timeout per command), and also if it writes anywhere in the copy but out/:
a repository file rewritten (even with the same content) or deleted, or a new file outside out/
(documented commands write their results under out/; a committed figure or table is updated by
copying it from there). The repository itself is compared before and after (`git status
--porcelain`). Commands that write to /tmp (a few sed-made model variants) are left alone.
Each command's line shows its wall time and the CPU time of its processes (exact with --jobs 1,
the default; with more jobs the files' commands overlap).

Exit status 0 if every command that ran passed, 1 otherwise (each failure names the file, line,
command, exit status and the tail of its output), 2 for a malformed marker or block.
"""
import argparse
import concurrent.futures
import hashlib
import os
import re
import resource
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

COMMAND_LANGUAGES = {"sh", "bash", "shell", "console"}
FENCE = re.compile(r"^( {0,3})(`{3,}|~{3,})\s*([^\s`]*)")
MARKER = re.compile(r"^\s*<!--\s*doc-test:(.*?)-->\s*$")  # a line of its own
MARKER_BODY = re.compile(r"^\s*(skip|slow)\s*\((.+)\)\s*$")
TAIL_LINES = 40


class DocError(Exception):
    pass


class Command:
    def __init__(self, path, line, text, mode, reason):
        self.path, self.line, self.text, self.mode, self.reason = path, line, text, mode, reason

    def where(self):
        return f"{self.path}:{self.line}"


def markdown_files(repo):
    files = [os.path.join(repo, "README.md")]
    for root, dirs, names in os.walk(os.path.join(repo, "docs")):
        dirs.sort()
        files += [os.path.join(root, n) for n in sorted(names) if n.endswith(".md")]
    examples = os.path.join(repo, "examples")
    for d in sorted(os.listdir(examples)):
        readme = os.path.join(examples, d, "README.md")
        if os.path.isfile(readme):
            files.append(readme)
    return [f for f in files if os.path.isfile(f)]


def complete(text):
    """Whether `text` is one whole shell command (no continuation, no open compound)."""
    if text.rstrip().endswith("\\"):
        return False
    return subprocess.run(["bash", "-n"], input=text, text=True,
                          capture_output=True).returncode == 0


def split_commands(rel, start, lines):
    """(line, text) of the commands of a block whose first content line is `start`."""
    transcript = any(l.startswith("$ ") for l in lines)
    out, buf, first = [], [], None
    for i, raw in enumerate(lines):
        lineno = start + i
        if transcript and not buf:
            if not raw.startswith("$ "):
                continue  # output of the command above
            raw = raw[2:]
        elif not transcript and raw.startswith("$ "):
            raw = raw[2:]
        if not buf and (not raw.strip() or raw.lstrip().startswith("#")):
            continue
        if not buf:
            first = lineno
        buf.append(raw)
        text = "\n".join(buf)
        if complete(text):
            out.append((first, text))
            buf = []
    if buf:
        raise DocError(f"{rel}:{first}: the command does not end (a trailing backslash or an "
                       f"open compound command at the end of its block): {buf[0].strip()}")
    return out


def extract(repo, path):
    rel = os.path.relpath(path, repo)
    lines = open(path, encoding="utf-8").read().split("\n")
    commands, i = [], 0
    pending = None  # (line, mode, reason) of a marker waiting for its block
    last_nonblank = None
    while i < len(lines):
        line = lines[i]
        m = FENCE.match(line)
        if not m:
            mk = MARKER.match(line)
            if mk:
                body = MARKER_BODY.match(mk.group(1))
                if not body:
                    raise DocError(f"{rel}:{i + 1}: a doc-test marker is `<!-- doc-test: skip "
                                   f"(reason) -->` or `<!-- doc-test: slow (reason) -->`")
                if pending:
                    raise DocError(f"{rel}:{pending[0]}: a doc-test marker without a command "
                                   f"block after it")
                pending = (i + 1, body.group(1), body.group(2).strip())
            elif line.strip() and pending:
                raise DocError(f"{rel}:{pending[0]}: a doc-test marker must be the last line "
                               f"before a command block's opening fence")
            if line.strip():
                last_nonblank = i
            i += 1
            continue
        fence, lang = m.group(2), m.group(3).lower()
        j = i + 1
        while j < len(lines):
            c = lines[j].strip()
            if c.startswith(fence[0] * len(fence)) and not c.strip(fence[0]):
                break
            j += 1
        block = lines[i + 1:j]
        if lang in COMMAND_LANGUAGES:
            mode, reason = ("run", "")
            if pending:
                mode, reason = pending[1], pending[2]
                pending = None
            for first, text in split_commands(rel, i + 2, block):
                commands.append(Command(rel, first, text, mode, reason))
        elif pending:
            raise DocError(f"{rel}:{pending[0]}: a doc-test marker before a block that is not "
                           f"a command block ({lang or 'no language'})")
        last_nonblank = j
        i = j + 1
    if pending:
        raise DocError(f"{rel}:{pending[0]}: a doc-test marker without a command block after it")
    return commands


def repo_files(repo):
    try:
        out = subprocess.run(["git", "-C", repo, "ls-files", "-z", "--cached", "--others",
                              "--exclude-standard"], check=True, capture_output=True).stdout
        names = [n for n in out.decode().split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = []
        for root, dirs, files in os.walk(repo):
            rel = os.path.relpath(root, repo)
            dirs[:] = [d for d in dirs if not (rel == "." and (d.startswith("build") or
                                                               d in (".git", "out")))]
            names += [os.path.normpath(os.path.join(rel, f)) for f in files]
    return sorted(n for n in names if os.path.isfile(os.path.join(repo, n))
                  and n != "build" and not n.startswith(("build/", "build-", "out/")))


def make_scratch(repo, build, files, parent):
    root = tempfile.mkdtemp(prefix="doc-commands-", dir=parent)
    for name in files:
        dst = os.path.join(root, name)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        shutil.copy2(os.path.join(repo, name), dst)
    os.symlink(os.path.abspath(build), os.path.join(root, "build"))
    return root


def scan(root):
    """{relative path: (size, mtime_ns)} of the files in the copy, out/ and build excepted."""
    state = {}
    for base, dirs, files in os.walk(root):
        rel = os.path.relpath(base, root)
        if rel == ".":
            dirs[:] = [d for d in dirs if d not in ("out", "build")]
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for f in files:
            p = os.path.join(base, f)
            st = os.lstat(p)
            state[os.path.normpath(os.path.join(rel, f))] = (st.st_size, st.st_mtime_ns)
    return state


def digest(path):
    with open(path, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def writes_outside_out(repo, before, after, root):
    """What a command wrote in the copy outside out/ (a rewrite with the same content, too)."""
    found = []
    for name, stamp in after.items():
        if name not in before:
            found.append(f"created {name}")
        elif stamp != before[name]:
            same = digest(os.path.join(root, name)) == digest(os.path.join(repo, name))
            found.append(f"{'rewrote' if same else 'modified'} {name}")
    found += [f"deleted {name}" for name in before if name not in after]
    return found


def restore(repo, root, changes):
    for c in changes:
        verb, name = c.split(" ", 1)
        p = os.path.join(root, name)
        if verb == "created":
            os.remove(p)
        else:
            shutil.copy2(os.path.join(repo, name), p)


def paraview_target(text):
    try:
        words = shlex.split(text, comments=True)
    except ValueError:
        return None
    if len(words) >= 2 and words[0] == "paraview":
        return words[1]
    return None


def tail(text, n=TAIL_LINES):
    lines = text.replace("\r", "\n").rstrip().split("\n")
    return "\n".join(("    " + l) for l in lines[-n:])


def run_file(repo, build, files, parent, commands, timeout, keep, env):
    """Runs one Markdown file's commands in its own copy; returns (results, scratch)."""
    root = make_scratch(repo, build, files, parent)
    results = []
    state = scan(root)
    try:
        for c in commands:
            t0 = time.monotonic()
            target = paraview_target(c.text)
            if target is not None:
                ok = os.path.exists(os.path.join(root, target))
                results.append((c, ok, 0.0, 0.0, "viewer not started; " +
                                ("its file exists" if ok else f"its file {target} is missing")))
                continue
            cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            p = subprocess.Popen(["bash", "-e", "-c", c.text], cwd=root, env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL, start_new_session=True)
            try:
                out, _ = p.communicate(timeout=timeout)
                code = p.returncode
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                out, _ = p.communicate()
                code = None
            dt = time.monotonic() - t0
            cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = cpu1.ru_utime + cpu1.ru_stime - cpu0.ru_utime - cpu0.ru_stime
            text = out.decode(errors="replace")
            now = scan(root)
            changes = writes_outside_out(repo, state, now, root)
            if changes:
                restore(repo, root, changes)
                now = scan(root)
            state = now
            if code is None:
                results.append((c, False, dt, cpu, f"timed out after {timeout:.0f} s\n" + tail(text)))
            elif code != 0:
                results.append((c, False, dt, cpu, f"exit status {code}\n" + tail(text)))
            elif changes:
                results.append((c, False, dt, cpu, "writes outside out/: " + ", ".join(changes[:10])
                                + ("" if len(changes) <= 10 else f" (+{len(changes) - 10} more)")))
            else:
                results.append((c, True, dt, cpu, ""))
    finally:
        if not keep:
            shutil.rmtree(root, ignore_errors=True)
    return results, root


def git_status(repo):
    try:
        return subprocess.run(["git", "-C", repo, "status", "--porcelain",
                               "--untracked-files=all"], check=True, capture_output=True,
                              text=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repo", default=os.path.normpath(os.path.join(here, "..", "..")))
    ap.add_argument("--build", help="the build folder (default REPO/build)")
    ap.add_argument("--slow", action="store_true", help="also the commands marked slow")
    ap.add_argument("--list", action="store_true", help="list the commands, run nothing")
    ap.add_argument("--only", help="only Markdown files whose path contains this")
    ap.add_argument("--timeout", type=float, default=300.0, help="per command, s (default 300)")
    ap.add_argument("--keep", action="store_true", help="keep the scratch folders")
    ap.add_argument("--jobs", type=int, default=1, help="Markdown files run in parallel")
    a = ap.parse_args()
    repo = os.path.abspath(a.repo)
    build = os.path.abspath(a.build or os.path.join(repo, "build"))

    try:
        per_file = [(f, extract(repo, f)) for f in markdown_files(repo)]
    except DocError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if a.only:
        per_file = [(f, c) for f, c in per_file if a.only in os.path.relpath(f, repo)]
    per_file = [(f, c) for f, c in per_file if c]
    if a.list:
        for _, cs in per_file:
            for c in cs:
                tag = c.mode + (f" ({c.reason})" if c.reason else "")
                print(f"{c.where():48} {tag:6.60}  {c.text.splitlines()[0][:100]}")
        return 0
    if not os.path.isfile(os.path.join(build, "isoflex")):
        print(f"error: no isoflex in {build} (--build)", file=sys.stderr)
        return 2

    status_before = git_status(repo)
    files = repo_files(repo)
    parent = tempfile.mkdtemp(prefix="doc-commands-")
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONDONTWRITEBYTECODE="1",
               MPLCONFIGDIR=os.path.join(parent, "matplotlib"))
    env.pop("DISPLAY", None)
    todo = [(f, [c for c in cs if c.mode == "run" or (a.slow and c.mode == "slow")], cs)
            for f, cs in per_file]
    t0 = time.monotonic()
    failures, ran, not_run, cpu_time = [], 0, [], 0.0
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        jobs = [(f, cs, pool.submit(run_file, repo, build, files, parent, run, a.timeout, a.keep,
                                    env)) for f, run, cs in todo if run]
        for f, cs, job in jobs:
            results, root = job.result()
            for c, ok, dt, cpu, note in results:
                ran += 1
                cpu_time += cpu
                print(f"{'ok  ' if ok else 'FAIL'} {dt:6.1f} s {cpu:6.1f} s cpu  {c.where()}  "
                      f"{c.text.splitlines()[0][:90]}" + (f"  [{note}]" if ok and note else ""),
                      flush=True)
                if not ok:
                    failures.append((c, note))
            if a.keep:
                print(f"     scratch: {root}")
    for _, _, cs in todo:
        not_run += [c for c in cs if c.mode == "skip" or (c.mode == "slow" and not a.slow)]
    if not a.keep:
        shutil.rmtree(parent, ignore_errors=True)
    status_after = git_status(repo)

    for c, note in failures:
        print(f"\n{c.where()}: FAILED\n  $ {c.text}\n  {note}", file=sys.stderr)
    if status_before is not None and status_after != status_before:
        print("\nthe repository changed while the commands ran (git status --porcelain):\n"
              f"before:\n{status_before}after:\n{status_after}", file=sys.stderr)
        failures.append((None, "repository changed"))
    skipped = sum(c.mode == "skip" for c in not_run)
    print(f"\n{ran} commands run in {time.monotonic() - t0:.1f} s ({cpu_time:.1f} s cpu), "
          f"{len(failures)} failed; "
          f"not run: {skipped} skip, {len(not_run) - skipped} slow"
          + ("" if a.slow else " (--slow runs those)"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
