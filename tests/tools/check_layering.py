#!/usr/bin/env python3
"""The core's stages depend downwards only (ctest layering; python3, standard library only).

  check_layering.py [--core DIR]

DIR (default: filter_vertex_brdf/core beside this script's repository) holds one folder per stage
and stages.txt, the stage order: one level a line, lowest first, stages on one line separated by
spaces; '#' starts a comment. Every #include "<stage>/<name>" of the .h and .cpp files under DIR is
read, and the script exits 1 naming every failure:
 1. an include of a stage on a later line (up the order), or of another stage on the same line;
 2. a cycle between stages (found on the include graph itself, so a wrong order in stages.txt
    cannot hide one);
 3. a stage folder that stages.txt does not list, or a listed stage without a folder;
 4. an include naming a file that does not exist.
Prints the stage graph when it passes.
"""
import argparse
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*"([A-Za-z0-9_]+)/([^"]+)"', re.MULTILINE)
SOURCE_EXTENSIONS = (".h", ".hpp", ".cpp", ".cc")


def read_levels(path):
    """{stage: level} from stages.txt (0 for the first line of stages), and the problems found in it."""
    levels, problems, level = {}, [], 0
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            words = line.split("#", 1)[0].split()
            for stage in words:
                if stage in levels:
                    problems.append(f"{path}:{number}: stage '{stage}' listed twice")
                levels[stage] = level
            level += bool(words)
    return levels, problems


def stage_folders(core):
    return sorted(d for d in os.listdir(core)
                  if os.path.isdir(os.path.join(core, d)) and not d.startswith("."))


def includes(core, stage):
    """(file, line, included stage, included path) for every stage include of a stage's sources."""
    found = []
    for root, _, files in os.walk(os.path.join(core, stage)):
        for name in sorted(files):
            if not name.endswith(SOURCE_EXTENSIONS):
                continue
            path = os.path.join(root, name)
            with open(path, encoding="utf-8", errors="replace") as f:
                text = f.read()
            for m in INCLUDE.finditer(text):
                line = text.count("\n", 0, m.start()) + 1
                found.append((os.path.relpath(path, core), line, m.group(1), m.group(1) + "/" + m.group(2)))
    return found


def find_cycle(graph):
    """A list of stages forming a cycle in {stage: set(stages)}, or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                cycle = visit(nxt)
                if cycle:
                    return cycle
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node)
            if cycle:
                return cycle
    return None


def check(core):
    """(failures, graph) for the tree under `core`."""
    failures = []
    order = os.path.join(core, "stages.txt")
    if not os.path.isfile(order):
        return [f"{order}: missing (the stage order)"], {}
    levels, problems = read_levels(order)
    failures += problems
    folders = stage_folders(core)
    failures += [f"{order}: stage folder '{d}' is not listed" for d in folders if d not in levels]
    failures += [f"{order}: listed stage '{s}' has no folder" for s in levels if s not in folders]
    graph = {stage: set() for stage in folders}
    for stage in folders:
        for path, line, target, included in includes(core, stage):
            if target not in folders:
                continue  # not a stage: a library's header ("opencv2/...", "vcg/...")
            where = f"{path}:{line}: #include \"{included}\""
            if not os.path.isfile(os.path.join(core, included)):
                failures.append(f"{where}: no such file")
            if target == stage:
                continue
            graph[stage].add(target)
            if stage in levels and target in levels:
                if levels[target] > levels[stage]:
                    failures.append(f"{where}: '{stage}' includes '{target}', a later stage in stages.txt")
                elif levels[target] == levels[stage]:
                    failures.append(f"{where}: '{stage}' includes '{target}', a stage on the same line of stages.txt")
    cycle = find_cycle(graph)
    if cycle:
        failures.append("include cycle between stages: " + " -> ".join(cycle))
    return failures, graph


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--core", default=os.path.join(here, "..", "..", "filter_vertex_brdf", "core"))
    args = parser.parse_args()
    core = os.path.normpath(args.core)
    failures, graph = check(core)
    if failures:
        for f in failures:
            print("LAYERING:", f)
        print(f"check_layering: {len(failures)} failure(s) in {core}")
        return 1
    for stage in sorted(graph):
        print(f"  {stage} -> {', '.join(sorted(graph[stage])) or '(nothing)'}")
    print(f"check_layering: {core}: {len(graph)} stages, includes down the order only, no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
