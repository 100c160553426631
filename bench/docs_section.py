"""Rewrites one marked part of a markdown file in place (atomically), leaving the rest as it is."""
import os


def replace_between(path, start, end, text):
    """Puts `text` between the markers `start` and `end` of `path`; both must be there, start first."""
    doc = open(path).read()
    if start not in doc or end not in doc:
        raise SystemExit(f"{path}: markers {start.strip()!r} ... {end.strip()!r} not found")
    i, j = doc.index(start) + len(start), doc.index(end)
    if j < i:
        raise SystemExit(f"{path}: {end.strip()!r} comes before {start.strip()!r}")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(doc[:i] + text + ("" if text.endswith("\n") else "\n") + doc[j:])
    os.replace(tmp, path)
