#!/usr/bin/env python3
"""Checks that every relative Markdown link [text](file.md#anchor) in the
tree resolves: the file exists and, with an anchor, the file has a heading
whose GitHub anchor (lowercase, punctuation removed, spaces to '-',
duplicates -1, -2) is that anchor. Catches a section renamed or moved
while a page still links to it.

    check_doc_links.py [ROOT]    # exit 1 and a line per broken link
"""
import os
import re
import sys

SKIP_DIRS = {".git", "build", "node_modules"}
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def slug(text):
    text = text.replace("`", "").replace("*", "").strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        found, counts, fence = set(), {}, False
        with open(path, encoding="utf-8") as f:
            for line in f:
                if line.lstrip().startswith("```"):
                    fence = not fence
                    continue
                m = None if fence else HEADING.match(line)
                if m:
                    s = slug(m.group(2))
                    n = counts.get(s, 0)
                    counts[s] = n + 1
                    found.add(s if n == 0 else f"{s}-{n}")
        cache[path] = found
    return cache[path]


def main(root):
    broken = 0
    for d, dirs, files in os.walk(root):
        dirs[:] = [x for x in dirs if x not in SKIP_DIRS and not x.startswith((".venv", "build-"))]
        for name in files:
            if not name.endswith(".md"):
                continue
            path = os.path.join(d, name)
            text = open(path, encoding="utf-8").read()
            text = re.sub(r"```.*?```", "", text, flags=re.S)
            for target in LINK.findall(text):
                if re.match(r"[a-z]+:", target):
                    continue
                file, _, anchor = target.partition("#")
                dest = os.path.normpath(os.path.join(d, file)) if file else path
                if not os.path.exists(dest):
                    print(f"{path}: {target}: no such file")
                    broken += 1
                elif anchor and dest.endswith(".md") and anchor not in anchors(dest):
                    print(f"{path}: {target}: no such heading")
                    broken += 1
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
