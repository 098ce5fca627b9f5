#!/usr/bin/env python3
"""Run bake on every row of expectations.tsv and check the bad-input contract (DESIGN.md §3, §6.4).

For each case:  BAKE INPUT -o TMP/out [ARGS] --spp 1 --texel-density 4   (timeout 60 s unless --timeout)

Checked:
  * the exit status is the expected one; never a signal, never a timeout;
  * stderr holds no sanitizer report, 'terminate called', etc.;
  * on a non-zero exit: exactly one line containing 'error:', of the form 'bake: error: ...',
    as the last line, naming the input file, and containing the expected element substring
    (matched after the file name is removed, so 'asset' cannot match 'asset_missing.gltf');
    every other line starts with 'bake: warning:';
  * on exit 0: no 'error:' line and OUT/manifest.json exists;
  * when the row asks for it, at least one 'bake: warning:' line;
  * nothing is left behind: on failure TMP is empty (no OUT, no OUT.tmp*, no cache), on success TMP
    holds only OUT and the bundle cache beside it (.exitance-cache); no new file appears next to the
    input.

Usage:
  run_bad_input.py [--bake PATH] [--only SUBSTRING] [--assimp-root DIR] [--corpus hostile|assimp|all]
                   [--expectations FILE] [--timeout S] [--jobs N] [--keep] [--verbose]
Prints one line per case and a final line 'N passed, M failed'.  Exit status: 0 all passed,
1 some failed, 77 nothing to run (the assimp corpus is not installed), 2 usage error.
Standard library only.
"""
import argparse
import concurrent.futures
import os
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
SKIP = 77
CRASH_MARKERS = ("AddressSanitizer", "LeakSanitizer", "UndefinedBehaviorSanitizer", "ThreadSanitizer",
                 "MemorySanitizer", "runtime error:", "terminate called", "Segmentation fault",
                 "core dumped", "Assertion", "Aborted", "stack-overflow", "double free")


class Case:
    def __init__(self, corpus, path, args, exit_, error, warning, note, lineno):
        self.corpus, self.path, self.note, self.lineno = corpus, path, note, lineno
        self.args = [] if args == "-" else shlex.split(args)
        self.exits = [int(x) for x in exit_.split("|")]
        self.errors = None if error in ("-", "*") else error.split("|")
        self.warning = warning == "*"

    @property
    def name(self):
        return "%s/%s%s" % (self.corpus, self.path, (" " + " ".join(self.args)) if self.args else "")


def read_cases(tsv):
    cases = []
    with open(tsv, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            cols = line.split("\t")
            if len(cols) < 6:
                raise SystemExit("%s:%d: expected 6 or 7 tab-separated columns, got %d" % (tsv, n, len(cols)))
            cases.append(Case(*cols[:6], cols[6] if len(cols) > 6 else "-", n))
    return cases


def listing(d):
    try:
        return set(os.listdir(d))
    except OSError:
        return set()


def run_case(case, input_path, bake, timeout, keep):
    """Returns (ok, problems, stderr)."""
    tmp = tempfile.mkdtemp(prefix="badinput-")
    out = os.path.join(tmp, "out")
    cmd = [bake, input_path, "-o", out] + case.args + ["--spp", "1", "--texel-density", "4"]
    input_dir = os.path.dirname(input_path)
    before = listing(input_dir)
    problems = []
    stderr = ""
    try:
        p = subprocess.Popen(cmd, cwd=tmp, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, start_new_session=True)
        try:
            _, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            _, err = p.communicate()
            stderr = err.decode("utf-8", "replace")
            return False, ["timed out after %d s (hang?)" % timeout], stderr
        stderr = err.decode("utf-8", "replace")
        rc = p.returncode
        lines = [l for l in stderr.splitlines() if l.strip()]

        if rc < 0:
            try:
                sig = signal.Signals(-rc).name
            except ValueError:
                sig = str(-rc)
            problems.append("killed by signal %s" % sig)
        elif rc not in case.exits:
            problems.append("exit %d, expected %s" % (rc, "|".join(map(str, case.exits))))
        for m in CRASH_MARKERS:
            if m in stderr:
                problems.append("stderr contains %r" % m)
                break

        error_lines = [l for l in lines if "error:" in l]
        warnings = [l for l in lines if l.startswith("bake: warning:")]
        if rc > 0:
            if len(error_lines) != 1:
                problems.append("%d lines contain 'error:', expected exactly 1" % len(error_lines))
            if error_lines:
                e = error_lines[0]
                if not e.startswith("bake: error: "):
                    problems.append("error line does not start with 'bake: error: '")
                if lines[-1] != e:
                    problems.append("error line is not the last line of stderr")
                base = os.path.basename(input_path)
                if base not in e:
                    problems.append("error line does not name the input file %s" % base)
                rest = e.replace(input_path, "").replace(base, "")
                if case.errors and not any(s in rest for s in case.errors):
                    problems.append("error line lacks %s" % " or ".join(repr(s) for s in case.errors))
                parts = rest.split(": ")
                if len(parts) < 5:  # 'bake', 'error', '' (file removed), element, problem
                    problems.append("error line is not 'bake: error: FILE: ELEMENT: PROBLEM'")
            others = [l for l in lines if l not in error_lines and not l.startswith("bake: warning:")]
            if others:
                problems.append("stderr has %d line(s) that are neither the error nor 'bake: warning:'"
                                % len(others))
        elif rc == 0:
            if error_lines:
                problems.append("exit 0 but stderr has %d 'error:' line(s)" % len(error_lines))
            if not os.path.isfile(os.path.join(out, "manifest.json")):
                problems.append("exit 0 but OUT/manifest.json does not exist")
        if case.warning and not warnings:
            problems.append("expected a 'bake: warning:' line")

        left = sorted(listing(tmp))
        if rc != 0 and left:
            problems.append("left behind after failure: %s" % ", ".join(left))
        elif rc == 0 and left != ["out"]:
            extra = [x for x in left if x not in ("out", ".exitance-cache")]  # the bundle cache sits beside OUT
            if extra:
                problems.append("left behind next to OUT: %s" % ", ".join(extra))
        new = sorted(listing(input_dir) - before)
        if new:
            problems.append("new file(s) next to the input: %s" % ", ".join(new))
        return not problems, problems, stderr
    finally:
        if keep:
            print("  kept %s" % tmp, flush=True)
        else:
            shutil.rmtree(tmp, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bake", default=os.environ.get("BAKE", os.path.join(REPO, "build", "bake", "bake")))
    ap.add_argument("--only", default=None, help="run only cases whose 'corpus/path args' contains this")
    ap.add_argument("--assimp-root", default="/usr/share/assimp/models/glTF2")
    ap.add_argument("--corpus", choices=("hostile", "assimp", "all"), default="all")
    ap.add_argument("--expectations", default=os.path.join(HERE, "expectations.tsv"))
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--keep", action="store_true", help="keep each case's temporary folder")
    ap.add_argument("--verbose", "-v", action="store_true", help="print stderr of passing cases too")
    a = ap.parse_args()

    roots = {"hostile": os.path.join(HERE, "hostile"), "assimp": a.assimp_root}
    cases = [c for c in read_cases(a.expectations) if a.corpus in ("all", c.corpus)]
    if a.only:
        cases = [c for c in cases if a.only in c.name]
    if not os.path.isdir(a.assimp_root):
        skipped = [c for c in cases if c.corpus == "assimp"]
        if skipped:
            print("SKIP %d assimp cases: %s not found (install Debian's assimp-testmodels)"
                  % (len(skipped), a.assimp_root))
        cases = [c for c in cases if c.corpus != "assimp"]
        if not cases:
            print("0 passed, 0 failed (skipped)")
            return SKIP
    if not cases:
        print("no case matches")
        return 2
    bake = os.path.abspath(a.bake)
    if not (os.path.isfile(bake) and os.access(bake, os.X_OK)):
        print("bake binary not found or not executable: %s (use --bake)" % bake)
        return 2

    def job(c):
        path = os.path.join(roots[c.corpus], c.path)
        if not os.path.exists(path):
            return c, False, ["input %s does not exist" % path], ""
        return (c,) + run_case(c, path, bake, a.timeout, a.keep)

    passed = failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        for c, ok, problems, stderr in pool.map(job, cases):
            if ok:
                passed += 1
                print("PASS  %s" % c.name, flush=True)
            else:
                failed += 1
                print("FAIL  %s: %s" % (c.name, "; ".join(problems)), flush=True)
            if not ok or a.verbose:
                tail = stderr.splitlines()
                for l in tail[:12]:
                    print("      | %s" % l)
                if len(tail) > 12:
                    print("      | ... (%d more lines)" % (len(tail) - 12))
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
