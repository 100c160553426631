#!/usr/bin/env python3
"""The house rules of the source tree, checked on the sources (the standard library only).

1. Folders depend only downwards: each product folder may include headers of the folders named in
   ALLOWED below and of no other (docs/architecture.md draws the same arrows).
2. No two files include each other's headers (a.h/a.cpp including b.h while b.h/b.cpp includes a.h).
3. No function in product code is longer than MAX_FUNCTION_LINES lines.

Usage: layering_test.py SOURCE_DIR   (exit 0 when every rule holds; each violation is printed)
       layering_test.py --self-test    (a made-up tree breaking each rule once: each must be caught)
"""
import pathlib
import re
import sys

# Who may include whom. shaders/ holds the layouts, bindings and kernel parameters that C++ shares
# with GLSL, so the folders that talk to the GPU include it too.
ALLOWED = {
    "core": set(),
    "body": {"core"},
    "gpu": {"core", "shaders"},
    "sdf": {"core", "gpu", "shaders"},
    "sampler": {"core", "body", "gpu", "sdf", "shaders"},
    "sim": {"core", "gpu", "shaders"},
    "scene": {"core", "body", "sim"},
    "export": {"core", "scene", "sim"},
    "preview": {"core", "body", "gpu", "sdf", "sampler", "sim", "scene", "shaders"},
    "app": {"core", "body", "gpu", "sdf", "sampler", "sim", "scene", "export", "preview", "shaders"},
    "tools": {"core"},
    # The Python module: beside app/, the same libraries below it (it never includes app/).
    "python": {"core", "body", "gpu", "sdf", "sampler", "sim", "scene", "preview"},
}
MAX_FUNCTION_LINES = 100
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def product_files(root):
    for folder in ALLOWED:
        for path in sorted((root / folder).glob("*")):
            if path.suffix in (".h", ".cpp"):
                yield folder, path


def includes(path):
    return INCLUDE.findall(path.read_text(encoding="utf-8", errors="replace"))


def folder_arrows(root):
    problems = []
    for folder, path in product_files(root):
        for inc in includes(path):
            target = inc.split("/")[0] if "/" in inc else folder
            if target != folder and target not in ALLOWED[folder]:
                problems.append(f"{path.relative_to(root)} includes {inc}: {folder}/ may not depend on {target}/")
    return problems


def mutual_includes(root):
    """Module = a header and its .cpp; a module that includes another which includes it back is a circle."""
    uses = {}
    for _, path in product_files(root):
        module = str(path.relative_to(root).with_suffix(""))
        for inc in includes(path):
            other = str(pathlib.PurePosixPath(inc).with_suffix(""))
            if other != module:
                uses.setdefault(module, set()).add(other)
    problems = []
    for a, targets in uses.items():
        for b in targets:
            if a < b and a in uses.get(b, set()):
                problems.append(f"{a} and {b} include each other's headers")
    return problems


def strip_code(text):
    """The text with comments, string and character literals blanked (newlines kept)."""
    pattern = re.compile(r'//[^\n]*|/\*.*?\*/|R"(\w*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)
    return pattern.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), text)


FUNCTION_HEAD = re.compile(r"\)\s*(?:const|noexcept|override|final|mutable|&|->\s*[\w:<>,\s\*&]+|\s)*$")


def long_functions(root):
    """Outermost function bodies (a block whose head ends like a parameter list, not inside another
    function) longer than MAX_FUNCTION_LINES. Lambdas inside count towards their function."""
    problems = []
    for _, path in product_files(root):
        text = strip_code(path.read_text(encoding="utf-8", errors="replace"))
        stack = []  # (is_function, start_line) of each open brace
        head_start = 0
        line = 1
        for i, ch in enumerate(text):
            if ch == "\n":
                line += 1
            elif ch == "{":
                inside_function = any(is_fn for is_fn, _ in stack)
                head = text[head_start:i]
                is_fn = not inside_function and FUNCTION_HEAD.search(head) is not None
                stack.append((is_fn, line))
                head_start = i + 1
            elif ch == "}":
                if stack:
                    is_fn, start = stack.pop()
                    if is_fn and line - start + 1 > MAX_FUNCTION_LINES:
                        problems.append(f"{path.relative_to(root)}:{start}: a function of {line - start + 1} lines "
                                        f"(at most {MAX_FUNCTION_LINES})")
                head_start = i + 1
            elif ch == ";":
                head_start = i + 1
    return problems


def self_test():
    """Each rule catches the one break planted for it in a throw-away tree, and a clean tree passes."""
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        for folder in ALLOWED:
            (root / folder).mkdir()
        (root / "core/a.h").write_text('#include "core/b.h"\n')
        (root / "core/b.cpp").write_text('#include "core/a.h"\nint f() {\n  return 1;\n}\n')
        (root / "core/b.h").write_text("int f();\n")
        (root / "sim/engine.cpp").write_text('#include "scene/scene.h"\n')
        body = "\n".join(["  x += 1;"] * MAX_FUNCTION_LINES)
        (root / "scene/long.cpp").write_text(f"int g(int x) {{\n{body}\n  return x;\n}}\n"
                                             "struct S {\n  int h() const { return 2; }\n};\n")
        found = {"arrow": folder_arrows(root), "circle": mutual_includes(root), "long": long_functions(root)}
        expected = {"arrow": ["sim/engine.cpp includes scene/scene.h: sim/ may not depend on scene/"],
                    "circle": ["core/a and core/b include each other's headers"],
                    "long": [f"scene/long.cpp:1: a function of {MAX_FUNCTION_LINES + 3} lines (at most "
                             f"{MAX_FUNCTION_LINES})"]}
        if found != expected:
            print(f"self-test failed:\n  found    {found}\n  expected {expected}")
            return 1
        for planted in ("core/a.h", "sim/engine.cpp", "scene/long.cpp"):
            (root / planted).unlink()
        if folder_arrows(root) + mutual_includes(root) + long_functions(root):
            print("self-test failed: a clean tree was reported")
            return 1
    print("self-test passed: each rule caught its planted break")
    return 0


def main():
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    missing = [f for f in ALLOWED if not (root / f).is_dir()]
    if missing:
        print(f"layering_test: folders missing under {root}: {', '.join(missing)}")
        return 1
    problems = folder_arrows(root) + mutual_includes(root) + long_functions(root)
    for p in problems:
        print(p)
    files = sum(1 for _ in product_files(root))
    print(f"{files} product files checked: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
