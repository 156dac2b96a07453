#!/usr/bin/env python3
"""Checks on the repository's documents and comments.

--links: every relative link and image in every *.md file names a file that exists and, with
  '#anchor', a heading of that file (anchors as GitHub derives them from headings).
--comments: no code comment carries an issue number, a session stop number or a commit hash,
  and none outside tests/ and benchmarks/ a figure in dB;
  comments state the rule and why it holds, and the figures live in the benchmarks they name.
"""
import argparse
import pathlib
import re
import subprocess
import sys
import unicodedata

SKIPPED_DIRS = {"build", "build-asan", "build-fuzz", "out", ".git", "third_party"}


def repository_files(root, suffixes):
    """The files of the repository with these suffixes: tracked by git where it is a checkout."""
    try:
        listed = subprocess.run(["git", "-C", str(root), "ls-files", "--cached", "--others",
                                 "--exclude-standard"], check=True, capture_output=True,
                                text=True).stdout.split("\n")
        paths = [root / p for p in listed if p]
    except (OSError, subprocess.CalledProcessError):
        paths = [p for p in root.rglob("*") if p.is_file()]
    return sorted(p for p in paths
                  if p.suffix in suffixes and p.exists()
                  and not SKIPPED_DIRS.intersection(p.relative_to(root).parts))


def heading_anchors(text):
    """The anchors GitHub gives the headings of a Markdown text."""
    anchors, seen = set(), {}
    in_fence = False
    for line in text.split("\n"):
        if line.startswith("```"):
            in_fence = not in_fence
            continue
        match = None if in_fence else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not match:
            continue
        title = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", match.group(1))
        slug = "".join(c for c in title.lower()
                       if c in " -_" or unicodedata.category(c)[0] in "LN")
        slug = slug.replace(" ", "-")
        count = seen.get(slug, 0)
        seen[slug] = count + 1
        anchors.add(slug if count == 0 else f"{slug}-{count}")
    return anchors


LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^()\s]*(?:\([^()]*\)[^()\s]*)*)(?:\s+\"[^\"]*\")?\)")


def check_links(root):
    problems = []
    for path in repository_files(root, {".md"}):
        text = path.read_text(encoding="utf-8")
        in_fence = False
        for number, line in enumerate(text.split("\n"), 1):
            if line.startswith("```"):
                in_fence = not in_fence
            if in_fence:
                continue
            for target in LINK.findall(re.sub(r"`[^`]*`", "", line)):
                if re.match(r"^[a-z][a-z0-9+.-]*:", target) or not target:
                    continue  # http:, https:, mailto: ...
                file_part, _, anchor = target.partition("#")
                linked = (path.parent / file_part).resolve() if file_part else path
                where = f"{path.relative_to(root)}:{number}: ({target})"
                if not linked.exists():
                    problems.append(f"{where}: {file_part} does not exist")
                elif anchor and linked.suffix == ".md":
                    if anchor not in heading_anchors(linked.read_text(encoding="utf-8")):
                        problems.append(f"{where}: no heading #{anchor} in {linked.name}")
    return problems


COMMENT_MARKS = {".cc": "//", ".h": "//", ".cu": "//", ".py": "#", ".sh": "#", ".cmake": "#",
                 ".txt": "#"}
# An issue or stop number, or a commit hash (7 to 40 hex digits with at least one letter and one
# digit, standing alone), inside a comment.
FORBIDDEN = re.compile(r"\b(?:[Ii]ssues? #?\d+|[Ss]tops? \d+)\b|(?<![\w.-])(?=[0-9a-f]*[a-f])"
                       r"(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![\w.+-])")

# A measured figure in dB inside a library or tool comment; a test states its bound and a
# benchmark its criterion in dB, and a quoted title (a sensor's dynamic range) is not a figure.
DECIBELS = re.compile(r"[0-9]+(?:\.[0-9]+)? ?dB\b")
QUOTED = re.compile(r'"[^"]*("|$)')


def check_comments(root):
    problems = []
    for path in repository_files(root, set(COMMENT_MARKS)):
        if path.suffix == ".txt" and path.name != "CMakeLists.txt":
            continue
        mark = COMMENT_MARKS[path.suffix]
        for number, line in enumerate(path.read_text(encoding="utf-8",
                                                     errors="replace").split("\n"), 1):
            position = line.find(mark)
            if position < 0:
                continue
            comment = line[position:]
            if "sha256" in comment:
                continue  # a weights file's digest names the file, not a commit
            match = FORBIDDEN.search(comment)
            if match:
                problems.append(f"{path.relative_to(root)}:{number}: '{match.group(0)}' in a "
                                f"comment: {comment.strip()[:100]}")
            figure = DECIBELS.search(QUOTED.sub("", comment))
            if figure and path.relative_to(root).parts[0] not in ("tests", "benchmarks"):
                problems.append(f"{path.relative_to(root)}:{number}: '{figure.group(0)}' in a "
                                f"comment (the figure belongs in the benchmark the comment "
                                f"names): {comment.strip()[:100]}")
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", type=pathlib.Path, required=True)
    parser.add_argument("--links", action="store_true")
    parser.add_argument("--comments", action="store_true")
    args = parser.parse_args()
    root = args.root.resolve()
    problems = (check_links(root) if args.links else []) + \
        (check_comments(root) if args.comments else [])
    for problem in problems:
        print(problem)
    print(f"{len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
