#!/usr/bin/env python3
"""The manual's links and references must resolve (ctest docs_links; python3, standard library only).

  check_links.py [--root REPO]

Checks, and exits 1 naming every failure:
 1. every markdown link (and image) in README.md and docs/**/*.md that points to a local file or
    anchor: the file exists, and the anchor is a heading of the target (GitHub-style anchors:
    lowercase, punctuation dropped, spaces to '-', repeated headings suffixed -1, -2, ...);
 2. every reference to a README or docs section from filter_vertex_brdf/, shaders/, tests/ and .ci/:
    `README.md#anchor`, `docs/x.md#anchor`, `docs/x.md` (or any docs/ file), and the prose forms
    README "Section", README, "Section", README's "Section", README section "Section" (the named
    section must be a heading of README.md, or the start of one);
 3. README.md has at most 400 lines, and no issue number ("issue 12") or date (2026-12-04) appears in
    README.md or docs/ outside docs/decisions/ (the history lives there).
"""
import argparse
import os
import re
import sys
import unicodedata

MAX_README_LINES = 400
SCAN_DIRS = ("filter_vertex_brdf", "shaders", "tests", ".ci")
SCAN_EXTENSIONS = {".cpp", ".h", ".hpp", ".c", ".py", ".sh", ".cmake", ".txt", ".md", ".glsl", ".comp",
                   ".in", ".mlx", ".json"}
HISTORY = re.compile(r"issue [0-9]+|20[0-9]{2}-[0-9]{2}-[0-9]{2}", re.IGNORECASE)

# Markdown: [text](target) and ![alt](target); the target ends at the first space or ')'.
MD_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
# Code and scripts: README.md#anchor, docs/<path>[#anchor] (not part of a longer path or a URL).
CODE_ANCHOR_REF = re.compile(r"(?<![\w./-])(README\.md|docs/[\w./-]*\w)(#[\w-]+)?")
# Prose references by section name: README "X", README, "X", README's "X", README section "X",
# README ("X"). The name may run over a line break inside a comment.
CODE_NAMED_REF = re.compile(r"(?<![\w./-])README(?:\.md)?(?:'s)?(?:[\s,(]|//+|#+|\*+|\\)*"
                            r"(?:section(?:[\s(]|//+|#+|\*+)*)?\\?[\"\u201c]([^\"\u201d]{1,160}?)\\?[\"\u201d]")
COMMENT_PREFIX = re.compile(r"\n\s*(?://+|#+|\*+|--)?\s*")


def github_anchor(heading):
    """The anchor GitHub gives a heading: rendered text, lowercased, punctuation dropped, spaces to -."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links and images: their text
    text = text.replace("`", "").strip().lower()
    out = []
    for ch in text:
        cat = unicodedata.category(ch)
        if ch in " -_" or cat[0] in "LNM":
            out.append("-" if ch == " " else ch)
    return "".join(out)


def strip_code(markdown):
    """Markdown without fenced code blocks and inline code spans (links there are not links)."""
    lines, fenced = [], False
    for line in markdown.split("\n"):
        if re.match(r"^\s*(```|~~~)", line):
            fenced = not fenced
            lines.append("")
            continue
        lines.append("" if fenced else re.sub(r"`[^`]*`", "", line))
    return "\n".join(lines)


def headings(path, cache={}):
    """(anchors, heading texts) of a markdown file."""
    if path not in cache:
        anchors, texts, seen = set(), [], {}
        with open(path, encoding="utf-8") as f:
            text = f.read()
        fenced = False
        for line in text.split("\n"):
            if re.match(r"^\s*(```|~~~)", line):
                fenced = not fenced
                continue
            m = None if fenced else re.match(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if not m:
                continue
            base = github_anchor(m.group(2))
            n = seen.get(base, 0)
            seen[base] = n + 1
            anchors.add(base if n == 0 else f"{base}-{n}")
            texts.append(m.group(2).replace("`", "").strip())
        cache[path] = (anchors, texts)
    return cache[path]


def check_target(root, source, base_dir, target, failures, where):
    """A local link target (path relative to base_dir, optional #anchor) must exist."""
    path_part, _, anchor = target.partition("#")
    if path_part:
        full = os.path.normpath(os.path.join(base_dir, path_part))
        if not full.startswith(root):
            failures.append(f"{where}: '{target}' points outside the repository")
            return
        if not os.path.exists(full):
            failures.append(f"{where}: '{target}': no file {os.path.relpath(full, root)}")
            return
    else:
        full = source
    if anchor:
        if not full.endswith(".md") or os.path.isdir(full):
            failures.append(f"{where}: '{target}': an anchor into a file that is not markdown")
            return
        anchors, _ = headings(full)
        if anchor not in anchors:
            failures.append(f"{where}: '{target}': no heading with anchor #{anchor} in {os.path.relpath(full, root)}")


def markdown_files(root):
    files = [os.path.join(root, "README.md")]
    for dirpath, _, names in os.walk(os.path.join(root, "docs")):
        files += [os.path.join(dirpath, n) for n in sorted(names) if n.endswith(".md")]
    return [f for f in files if os.path.isfile(f)]


def check_markdown_links(root, failures):
    count = 0
    for path in markdown_files(root):
        with open(path, encoding="utf-8") as f:
            text = strip_code(f.read())
        for lineno, line in enumerate(text.split("\n"), 1):
            for m in MD_LINK.finditer(line):
                target = m.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE):  # http:, mailto:, ...
                    continue
                count += 1
                check_target(root, path, os.path.dirname(path), target, failures,
                             f"{os.path.relpath(path, root)}:{lineno}")
    return count


def code_files(root):
    here = os.path.abspath(__file__)
    for top in SCAN_DIRS:
        for dirpath, dirnames, names in os.walk(os.path.join(root, top)):
            dirnames[:] = [d for d in dirnames if not d.startswith(("build", "__pycache__")) and d != "node_modules"]
            for n in sorted(names):
                full = os.path.join(dirpath, n)
                ext = os.path.splitext(n)[1]
                if full == here:
                    continue
                if ext in SCAN_EXTENSIONS or n == "CMakeLists.txt" or (top == ".ci" and ext == ""):
                    yield full


def check_code_references(root, failures):
    readme = os.path.join(root, "README.md")
    _, readme_headings = headings(readme)
    lowered = [h.lower() for h in readme_headings]
    count = 0
    for path in code_files(root):
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue
        rel = os.path.relpath(path, root)
        for m in CODE_ANCHOR_REF.finditer(text):
            lineno = text.count("\n", 0, m.start()) + 1
            target = m.group(1) + (m.group(2) or "")
            if m.group(1) == "README.md" and not m.group(2):
                continue  # the README as a whole (e.g. a generated sample's README.md)
            if m.group(1).startswith("docs/") and not os.path.splitext(m.group(1))[1] and not m.group(2):
                if not os.path.isdir(os.path.join(root, m.group(1))):
                    failures.append(f"{rel}:{lineno}: '{target}': no such folder")
                count += 1
                continue
            count += 1
            check_target(root, readme, root, target, failures, f"{rel}:{lineno}")
        for m in CODE_NAMED_REF.finditer(text):
            lineno = text.count("\n", 0, m.start()) + 1
            name = re.sub(r"\s+", " ", COMMENT_PREFIX.sub(" ", m.group(1))).replace("`", "").strip()
            name = name.replace('\\', '')
            count += 1
            key = name.lower()
            if not any(h == key or h.startswith(key) for h in lowered):
                failures.append(f"{rel}:{lineno}: README section \"{name}\" does not exist "
                                f"(refer to README.md#anchor or docs/<file>.md#anchor)")
    return count


def check_readme_and_history(root, failures):
    with open(os.path.join(root, "README.md"), encoding="utf-8") as f:
        n = len(f.read().splitlines())
    if n > MAX_README_LINES:
        failures.append(f"README.md: {n} lines, more than {MAX_README_LINES}")
    for path in markdown_files(root):
        rel = os.path.relpath(path, root)
        if rel.split(os.sep)[:2] == ["docs", "decisions"]:
            continue
        with open(path, encoding="utf-8") as f:
            for lineno, line in enumerate(f, 1):
                m = HISTORY.search(line)
                if m:
                    failures.append(f"{rel}:{lineno}: history outside docs/decisions/: '{m.group(0)}'")
    return n


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", default=os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")))
    a = ap.parse_args()
    root = os.path.abspath(a.root)
    failures = []
    links = check_markdown_links(root, failures)
    refs = check_code_references(root, failures)
    lines = check_readme_and_history(root, failures)
    if failures:
        print(f"FAILED: {len(failures)} problem(s)")
        for f in failures:
            print("  " + f)
        return 1
    print(f"ok: {links} markdown links, {refs} references from code, tests and CI resolve; "
          f"README.md has {lines} lines; no history outside docs/decisions/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
