"""Runs the first ```python block under a README heading, so the README's example cannot rot.

Usage: run_readme_snippet.py README.md "From Python"   (run from anywhere: the snippet runs in the
README's folder, with this process's environment: PYTHONPATH must reach the module). Exit 0 when the
block runs; 1 with the reason when the heading or the block is missing or the block fails.
"""
import pathlib
import re
import subprocess
import sys


def snippet(readme, heading):
    """The first ```python block whose nearest heading above (outside code blocks) is `heading`."""
    current, block, in_fence = None, None, False
    for line in readme.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            if block is not None and in_fence:
                return "\n".join(block) + "\n"
            in_fence = not in_fence
            if in_fence and line.strip() == "```python" and current == heading:
                block = []
            continue
        if in_fence:
            if block is not None:
                block.append(line)
        elif re.match(r"#+ ", line):
            current = line.lstrip("#").strip()
    if current is None or block is None:
        raise SystemExit(f"{readme}: no ```python block under the heading '{heading}'")
    raise SystemExit(f"{readme}: the ```python block under '{heading}' is not closed")


def main():
    readme, heading = pathlib.Path(sys.argv[1]), sys.argv[2]
    code = snippet(readme, heading)
    result = subprocess.run([sys.executable, "-c", code], cwd=readme.parent)
    if result.returncode != 0:
        print(f"{readme}: the '{heading}' snippet exited {result.returncode}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
