#!/usr/bin/env python3
"""Run exitance-view on every row of view_expectations.tsv and check the bad-input contract (DESIGN.md §3).

The runner first bakes hostile/valid_cube.gltf (bake --spp 1 --texel-density 4 --no-cache) and derives
the fixture bundles named in the first column. For each row:
  EXITANCE_VIEW BUNDLE ARGS [-o OUT/view.png]   (timeout 60 s), OUT a fresh empty folder

Checked:
  * the exit status is the expected one; never a signal, never a timeout, no crash report on stderr;
  * on exit 2: stderr is exactly one line, 'exitance-view: error: ...', containing the expected
    substring, and OUT is still empty (no output file, no temporary file);
  * on exit 0: no 'error:' line and OUT holds exactly the one output file.

Usage: run_view_bad_input.py --bake PATH --view PATH [--only SUBSTRING] [--keep]
Prints one line per case and a final line 'N passed, M failed'. Exit 0 all passed, 1 some failed,
2 usage or fixture error. Standard library only.
"""
import argparse
import os
import shlex
import shutil
import signal
import subprocess
import sys
import struct
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from run_bad_input import CRASH_MARKERS  # noqa: E402  (one list of crash markers for both runners)


def read_cases(tsv):
    cases = []
    with open(tsv, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            cols = line.split("\t")
            if len(cols) < 4:
                raise SystemExit("%s:%d: expected 4 or 5 tab-separated columns, got %d" % (tsv, n, len(cols)))
            bundle, args, exit_, error = cols[:4]
            cases.append({"bundle": bundle, "args": [] if args == "-" else shlex.split(args), "exit": int(exit_),
                          "errors": None if error == "-" else error.split("|"),
                          "name": "%s %s" % (bundle, args)})
    return cases


def make_fixtures(bake, root):
    cube = os.path.join(HERE, "hostile", "valid_cube.gltf")
    fixtures = {"missing": os.path.join(root, "does-not-exist.bake")}
    for name, extra in (("cube", []), ("no_probes", ["--probes", "none"])):
        out = os.path.join(root, name + ".bake")
        subprocess.run([bake, cube, "-o", out, "--spp", "1", "--texel-density", "4", "--no-cache"] + extra,
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        fixtures[name] = out
    fixtures["no_scene_bin"] = os.path.join(root, "no_scene_bin.bake")
    shutil.copytree(fixtures["cube"], fixtures["no_scene_bin"])
    os.remove(os.path.join(fixtures["no_scene_bin"], "scene.bin"))
    fixtures["bad_scene_bin"] = os.path.join(root, "bad_scene_bin.bake")
    shutil.copytree(fixtures["cube"], fixtures["bad_scene_bin"])
    scene_bin = os.path.join(fixtures["bad_scene_bin"], "scene.bin")
    with open(scene_bin, "rb") as f:
        data = f.read()
    with open(scene_bin, "wb") as f:
        f.write(data[: len(data) // 2])
    make_textured_fixtures(bake, root, fixtures)
    fixtures["empty_folder"] = os.path.join(root, "empty_folder")
    os.mkdir(fixtures["empty_folder"])
    return fixtures


SCENE_HEADER = 160


def refresh_scene_checksums(data):
    """Recomputes scene.bin's payload and header CRC-32s (formats/scene_format.md) after an edit."""
    struct.pack_into("<I", data, 152, zlib.crc32(bytes(data[SCENE_HEADER:])) & 0xFFFFFFFF)
    struct.pack_into("<I", data, 156, zlib.crc32(bytes(data[:156])) & 0xFFFFFFFF)


def last_texture_record(data):
    """Offset of the last texture record of a version 2, 3 or 4 scene.bin with textures, no environment
    map and no tangents: the record that ends the file (u32 width, height, wrap_s, wrap_t, has_alpha, then pixels)."""
    for offset in range(len(data) - 20, SCENE_HEADER - 4, -4):
        w, h, _, _, alpha = struct.unpack_from("<5I", data, offset)
        if alpha in (0, 1) and 0 < w <= 65535 and 0 < h <= 65535 and offset + 20 + w * h * (12 + 4 * alpha) == len(data):
            return offset
    raise SystemExit("textured fixture: no texture record ends scene.bin")


def make_textured_fixtures(bake, root, fixtures):
    """hostile/valid_texture.gltf baked (scene.bin version 4 with one texture, no normal map), and its scene.bin
    truncated inside the texture, with an oversized texture (right checksums) and with a flipped
    texel byte (wrong checksum)."""
    out = os.path.join(root, "textured.bake")
    subprocess.run([bake, os.path.join(HERE, "hostile", "valid_texture.gltf"), "-o", out, "--spp", "1",
                    "--texel-density", "4", "--no-cache", "--probes", "none"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    fixtures["textured"] = out
    with open(os.path.join(out, "scene.bin"), "rb") as f:
        original = bytearray(f.read())
    if (struct.unpack_from("<I", original, 8)[0] not in (2, 3, 4) or struct.unpack_from("<I", original, 132)[0] != 1
            or struct.unpack_from("<I", original, 140)[0] != 0):
        raise SystemExit("textured fixture: scene.bin is not version 2, 3 or 4 with one texture and no tangents")
    texture = last_texture_record(original)
    truncated = original[: texture + 20 + 8]
    oversized = bytearray(original)
    struct.pack_into("<2I", oversized, texture, 65535, 65535)
    refresh_scene_checksums(oversized)
    flipped = bytearray(original)
    flipped[texture + 20 + 5] ^= 0x40
    for name, data in (("textured_truncated", truncated), ("textured_oversized", oversized),
                       ("textured_flipped", flipped)):
        fixtures[name] = os.path.join(root, name + ".bake")
        shutil.copytree(out, fixtures[name])
        with open(os.path.join(fixtures[name], "scene.bin"), "wb") as f:
            f.write(data)


def run_case(case, view, fixtures, timeout):
    out = tempfile.mkdtemp(prefix="badinput-view-")
    try:
        args = [a.replace("{out}", out) for a in case["args"]]
        if "-o" not in args:
            args += ["-o", os.path.join(out, "view.png")]
        cmd = [view, fixtures[case["bundle"]]] + args
        p = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             start_new_session=True)
        try:
            _, err = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            return ["timed out after %d s" % timeout], ""
        stderr = err.decode("utf-8", "replace")
        lines = [l for l in stderr.splitlines() if l.strip()]
        problems = []
        rc = p.returncode
        if rc < 0:
            problems.append("killed by signal %d" % -rc)
        elif rc != case["exit"]:
            problems.append("exit %d, expected %d" % (rc, case["exit"]))
        for m in CRASH_MARKERS:
            if m in stderr:
                problems.append("stderr contains %r" % m)
                break
        left = sorted(os.listdir(out))
        if rc != 0:
            if len(lines) != 1:
                problems.append("%d stderr lines, expected exactly 1" % len(lines))
            elif not lines[0].startswith("exitance-view: error: "):
                problems.append("the error line does not start with 'exitance-view: error: '")
            elif case["errors"] and not any(s in lines[0] for s in case["errors"]):
                problems.append("error line lacks %s" % " or ".join(repr(s) for s in case["errors"]))
            if left:
                problems.append("left behind after failure: %s" % ", ".join(left))
        else:
            if any("error:" in l for l in lines):
                problems.append("exit 0 but stderr has an 'error:' line")
            if len(left) != 1:
                problems.append("expected one output file, found: %s" % (", ".join(left) or "none"))
        return problems, stderr
    finally:
        shutil.rmtree(out, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bake", required=True)
    ap.add_argument("--view", required=True)
    ap.add_argument("--only", default=None)
    ap.add_argument("--expectations", default=os.path.join(HERE, "view_expectations.tsv"))
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--keep", action="store_true", help="keep the fixture bundles")
    a = ap.parse_args()
    cases = read_cases(a.expectations)
    if a.only:
        cases = [c for c in cases if a.only in c["name"]]
    root = tempfile.mkdtemp(prefix="badinput-view-fixtures-")
    try:
        try:
            fixtures = make_fixtures(os.path.abspath(a.bake), root)
        except (subprocess.CalledProcessError, OSError) as e:
            print("could not prepare the fixture bundles: %s" % e)
            return 2
        passed = failed = 0
        for c in cases:
            problems, stderr = run_case(c, os.path.abspath(a.view), fixtures, a.timeout)
            if problems:
                failed += 1
                print("FAIL  %s: %s" % (c["name"], "; ".join(problems)), flush=True)
                for l in stderr.splitlines()[:6]:
                    print("      | %s" % l)
            else:
                passed += 1
                print("PASS  %s" % c["name"], flush=True)
        print("%d passed, %d failed" % (passed, failed))
        return 1 if failed else 0
    finally:
        if a.keep:
            print("kept %s" % root)
        else:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
