#!/usr/bin/env python3
"""check_layering.py on made-up trees (ctest layering_checker; python3, standard library only).

Builds small core trees in a temporary folder and runs the checker on each: a tree whose includes
go down the order must pass; one with an include up the order, one with two stages of one line
including each other (a cycle), one with a stage folder stages.txt does not list and one with an
include of a missing file must each fail, naming the fault. Exits 1 naming every case that did
not behave so.
"""
import os
import subprocess
import sys
import tempfile

CHECKER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "check_layering.py")
ORDER = "# test order\nbase\nmid side\ntop\n"


def write(root, rel, text):
    path = os.path.join(root, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def good_tree(root):
    write(root, "stages.txt", ORDER)
    write(root, "base/a.h", "#pragma once\n#include <vector>\n")
    write(root, "mid/b.h", '#pragma once\n#include "base/a.h"\n')
    write(root, "side/c.h", '#pragma once\n#include "base/a.h"\n#include "opencv2/core.hpp"\n')
    write(root, "top/d.cpp", '#include "mid/b.h"\n#include "side/c.h"\n#include "top/d.h"\n')
    write(root, "top/d.h", "#pragma once\n")


CASES = [
    # (name, change to the good tree, text the failure must contain)
    ("upward include", lambda r: write(r, "base/e.cpp", '#include "top/d.h"\n'), "a later stage"),
    ("cycle on one line", lambda r: (write(r, "mid/f.h", '#include "side/c.h"\n'),
                                     write(r, "side/g.h", '#include "mid/b.h"\n')), "include cycle between stages"),
    ("unlisted stage", lambda r: write(r, "extra/h.h", '#include "base/a.h"\n'), "is not listed"),
    ("missing file", lambda r: write(r, "top/i.cpp", '#include "mid/nothing.h"\n'), "no such file"),
]


def run(root):
    p = subprocess.run([sys.executable, CHECKER, "--core", root], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       universal_newlines=True)
    return p.returncode, p.stdout


def main():
    failures = []
    with tempfile.TemporaryDirectory(prefix="layering_") as tmp:
        root = os.path.join(tmp, "good")
        good_tree(root)
        rc, out = run(root)
        if rc != 0:
            failures.append("a tree whose includes go down the order failed:\n" + out)
        for i, (name, change, expected) in enumerate(CASES):
            root = os.path.join(tmp, f"case{i}")
            good_tree(root)
            change(root)
            rc, out = run(root)
            if rc == 0 or expected not in out:
                failures.append(f"{name}: expected a failure naming '{expected}', got exit {rc}:\n{out}")
            else:
                print(f"{name}: refused as expected")
    for f in failures:
        print("FAIL:", f)
    print("test_check_layering:", "failed" if failures else f"{len(CASES)} faults refused, the good tree passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
