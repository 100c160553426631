#!/usr/bin/python3
"""Every link of the project's markdown stays inside the repository and lands: no http(s) or other
scheme, no path out of the tree, every linked file exists, and every #anchor into a markdown file is
one of its headings (GitHub's rule: lower case, punctuation dropped, spaces to hyphens, repeats
numbered). Fenced code blocks and inline code are not links. bench/ is left out: its notes are
fragments the generators copy into docs/benchmarks/ pages, where their links are checked.
Usage: links_test.py ROOT. Exit status 0 when every link lands; each broken one is printed."""
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
SKIP = {"bench", ".git"}
FENCE = re.compile(r"^(```|~~~).*?^\1", re.M | re.S)
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def anchor(heading):
    text = re.sub(r"`", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path):
    seen, found = {}, set()
    for line in FENCE.sub("", open(path, encoding="utf-8").read()).split("\n"):
        m = re.match(r"^#{1,6} (.*)", line)
        if m:
            a = anchor(m.group(1))
            n = seen.get(a, 0)
            seen[a] = n + 1
            found.add(a if n == 0 else f"{a}-{n}")
    return found


def markdown_files():
    for top, dirs, files in os.walk(ROOT):
        rel = os.path.relpath(top, ROOT)
        dirs[:] = [d for d in dirs if not (rel == "." and (d in SKIP or d.startswith("build") or d.startswith(".")))]
        yield from (os.path.join(top, f) for f in files if f.endswith(".md"))


def broken_links(path):
    text = FENCE.sub("", open(path, encoding="utf-8").read())
    text = re.sub(r"`[^`\n]*`", "", text)
    for target in LINK.findall(text):
        if re.match(r"[a-zA-Z][a-zA-Z0-9+.-]*:", target) or target.startswith("//"):
            yield target, "points outside the repository"
            continue
        file, _, frag = target.partition("#")
        dest = os.path.normpath(os.path.join(os.path.dirname(path), file)) if file else path
        if os.path.commonpath([dest, ROOT]) != ROOT:
            yield target, "leaves the repository"
        elif not os.path.exists(dest):
            yield target, "no such file"
        elif frag and dest.endswith(".md") and frag not in anchors(dest):
            yield target, f"no heading #{frag} in {os.path.relpath(dest, ROOT)}"


failures = 0
files = sorted(markdown_files())
for path in files:
    for target, why in broken_links(path):
        print(f"{os.path.relpath(path, ROOT)}: ({target}) {why}")
        failures += 1
print(f"{len(files)} markdown files, {failures} broken links")
sys.exit(1 if failures else 0)
