#!/usr/bin/env python3
"""The shader audit (docs/architecture.md, "Operations GLSL leaves undefined"): patterns in the GLSL
sources whose result the GLSL 4.50 specification leaves undefined, so that drivers may resolve them
differently (llvmpipe one way, NVIDIA another), checked on the sources (the standard library and
glslangValidator only).

Rules (a finding names the file, the line and the rule):
  shift-amount        a shift by a constant (or a #define'd constant) of 32 or more, or a negative one
  float-to-uint       uint()/uvec() of a float-valued expression that is not clamped to >= 0 first
                      (max(..., 0), clamp, abs): negative floats convert to undefined values
  uninitialised-read  a local scalar or vector declared without a value whose first use reads it
                      (not an assignment, not an `out` argument)
  pnanovdb-root-walk  a call into PNanoVDB's root walk (its 64-bit root key, which NVIDIA's GLSL
                      compiler computed wrong): every read finds its root tile in sdf::SparseField's
                      root table (common/sparse_field.glsl)
  glslang             a kernel that glslangValidator rejects in one of the variants the host compiles
                      (TS_FP64, a chunked field's TS_FIELD_CHUNKS, the probe's TS_PROBE_MODE); the
                      build validates the plain variant only
A line (or the line above it) holding `ts-audit: allow <rule> (<why>)` is exempt from that rule.
PNanoVDB.h's GLSL branch (the vendor header the kernels include) is checked by the first three rules
against KNOWN_VENDOR_FINDINGS below: a new finding there fails too.

Usage: shader_audit.py SOURCE_DIR [--glslang PATH] [--nanovdb-include DIR]
       shader_audit.py --self-test [--glslang PATH] [--nanovdb-include DIR]
"""
import argparse
import concurrent.futures
import pathlib
import re
import subprocess
import sys
import tempfile

KERNEL_STAGES = {".comp": "comp", ".vert": "vert", ".frag": "frag", ".geom": "geom"}
SOURCE_SUFFIXES = set(KERNEL_STAGES) | {".glsl", ".h"}
SUPPRESS = re.compile(r"ts-audit:\s*allow\s+([\w-]+)")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
DEFINE_INT = re.compile(r"^\s*#\s*define\s+(\w+)\s+(-?(?:0x[0-9a-fA-F]+|\d+))[uU]?\s*$", re.M)

FLOAT_TYPES = {"float", "double", "vec2", "vec3", "vec4", "dvec2", "dvec3", "dvec4", "mat2", "mat3", "mat4",
               "dmat2", "dmat3", "dmat4", "real", "real2", "real3", "real4", "pnanovdb_vec3_t"}
INT_TYPES = {"int", "uint", "bool", "ivec2", "ivec3", "ivec4", "uvec2", "uvec3", "uvec4", "bvec2", "bvec3",
             "bvec4", "pnanovdb_uint32_t", "pnanovdb_int32_t", "pnanovdb_bool_t", "pnanovdb_uint64_t",
             "pnanovdb_int64_t", "pnanovdb_coord_t"}
# Locals of these types are checked for reads before assignment: values, and PNanoVDB's buffer token,
# which every read passes along (its value is never used, but passing it reads it).
CHECKED_LOCAL_TYPES = FLOAT_TYPES | INT_TYPES | {"pnanovdb_buf_t"}
FLOAT_CALLS = ("floor", "ceil", "round", "roundEven", "trunc", "fract", "sqrt", "inversesqrt", "length",
               "distance", "dot", "exp", "exp2", "log", "log2", "pow", "sin", "cos", "tan", "asin", "acos",
               "atan", "mix", "smoothstep", "uintBitsToFloat", "intBitsToFloat", "float", "double")
INT_CALLS = ("int", "uint", "ivec2", "ivec3", "ivec4", "uvec2", "uvec3", "uvec4", "floatBitsToUint",
             "floatBitsToInt", "findLSB", "findMSB", "bitCount", "bitfieldExtract", "bitfieldInsert",
             "bitfieldReverse", "packHalf2x16", "packUnorm4x8", "atomicAdd", "atomicMin", "atomicMax")
SWIZZLE = re.compile(r"^[xyzw]{1,4}$|^[rgba]{1,4}$|^[stpq]{1,4}$")
FLOAT_LITERAL = re.compile(r"(?<![\w.])(?:\d+\.\d*|\.\d+|\d+(?=[eE][-+]?\d))(?:[eE][-+]?\d+)?(?:lf|LF|f|F)?(?![\w])")
ROOT_WALK = re.compile(r"\bpnanovdb_(?:root_find_tile|coord_to_key|readaccessor_get_\w+|readaccessor_is_active|"
                       r"root_get_value\w*|root_get_dim\w*|root_is_active\w*|root_get_child)\s*\(")

# Findings in PNanoVDB.h's GLSL branch, judged harmless for the way the kernels use it (see
# docs/architecture.md): (rule, function) -> why. A finding not listed here fails the audit.
KNOWN_VENDOR_FINDINGS = {
    ("uninitialised-read", name): "`level` is passed uninitialised to an inout parameter that every path of the "
                                  "callee writes before reading; the undefined copy-in is never used"
    for name in ("pnanovdb_lower_get_value_address", "pnanovdb_upper_get_value_address",
                 "pnanovdb_root_get_value_address", "pnanovdb_root_get_value_address_bit",
                 "pnanovdb_lower_get_value_address_and_cache", "pnanovdb_upper_get_value_address_and_cache",
                 "pnanovdb_root_get_value_address_and_cache", "pnanovdb_readaccessor_get_value_address",
                 "pnanovdb_readaccessor_get_value_address_bit")
}


def strip_comments(text):
    """The text with comments blanked (newlines kept, so line numbers hold)."""
    return re.sub(r"//[^\n]*|/\*.*?\*/", lambda m: re.sub(r"[^\n]", " ", m.group(0)), text, flags=re.S)


def line_of(text, pos):
    return text.count("\n", 0, pos) + 1


def matching(text, open_pos, open_ch="(", close_ch=")"):
    """The position of the bracket closing the one at open_pos, or len(text)."""
    depth = 0
    for i in range(open_pos, len(text)):
        if text[i] == open_ch:
            depth += 1
        elif text[i] == close_ch:
            depth -= 1
            if depth == 0:
                return i
    return len(text)


class Source:
    """One file: its raw lines (for suppressions) and its code without comments."""

    def __init__(self, name, text, line_offset=0):
        self.name = name
        self.raw_lines = text.split("\n")
        self.code = strip_comments(text)
        self.line_offset = line_offset  # added to reported lines (a vendor header inside a preprocessed file)

    def suppressed(self, line, rule):
        for n in (line - 1, line - 2):
            if 0 <= n < len(self.raw_lines):
                m = SUPPRESS.search(self.raw_lines[n])
                if m and m.group(1) == rule:
                    return True
        return False

    def where(self, pos):
        return line_of(self.code, pos)


def declared_types(code):
    """name -> set of declared types, for every declaration in `code` (variables, parameters, members)."""
    types = {}
    all_types = "|".join(sorted(FLOAT_TYPES | INT_TYPES, key=len, reverse=True))
    for m in re.finditer(rf"\b({all_types})\s+(\w+)\s*(?:\[[^\]]*\])?\s*[;,=)\[]", code):
        types.setdefault(m.group(2), set()).add(m.group(1))
    for m in re.finditer(rf"\b({all_types})\s+(\w+)\s*\(", code):  # functions: their return types
        types.setdefault(m.group(2) + "()", set()).add(m.group(1))
    return types


def replace_calls(expr, names, by="0"):
    """`expr` with every call to one of `names` (with its arguments) replaced by `by`."""
    pattern = re.compile(r"\b(?:%s)\s*\(" % "|".join(names))
    while True:
        m = pattern.search(expr)
        if not m:
            return expr
        end = matching(expr, m.end() - 1)
        expr = expr[:m.start()] + by + expr[end + 1:]


def chain_type(base, members, types):
    """Float or int for an identifier chain (a.b[i].c.x), by the last declared name in it."""
    kind = None
    for name in [base] + members:
        if SWIZZLE.match(name) and kind is not None:
            continue
        declared = types.get(name)
        if declared:
            floats = declared & FLOAT_TYPES
            kind = "float" if floats == declared else ("int" if not floats else "mixed")
    return kind


def is_float_expr(expr, types):
    returns = {name[:-2]: t for name, t in types.items() if name.endswith("()")}
    int_functions = [name for name, t in returns.items() if not t & FLOAT_TYPES]
    float_functions = [name for name, t in returns.items() if t <= FLOAT_TYPES]
    expr = replace_calls(expr, list(INT_CALLS) + int_functions)
    if float_functions and re.search(r"\b(?:%s)\s*\(" % "|".join(float_functions), expr):
        return True
    expr = re.sub(r"\.\s*length\s*\(\s*\)", "", expr)
    if FLOAT_LITERAL.search(expr) or re.search(r"\b(?:%s)\s*\(" % "|".join(FLOAT_CALLS), expr):
        return True
    for m in re.finditer(r"\b([A-Za-z_]\w*)((?:\s*\[[^\]]*\]|\s*\.\s*[A-Za-z_]\w*)*)", expr):
        members = re.findall(r"\.\s*([A-Za-z_]\w*)", re.sub(r"\[[^\]]*\]", "", m.group(2)))
        if chain_type(m.group(1), members, types) == "float":
            return True
    return False


def clamped_non_negative(expr):
    expr = expr.strip()
    if re.match(r"(?:clamp|abs)\s*\(", expr):
        return True
    m = re.match(r"max\s*\(", expr)
    if m and matching(expr, m.end() - 1) == len(expr) - 1:
        last = expr[m.end():-1].rsplit(",", 1)[-1].strip()
        return re.fullmatch(r"\d+(?:\.\d*)?(?:[eE][-+]?\d+)?[uUfF]?|\w*vec\d\(\s*\d+(?:\.\d*)?\s*\)", last) is not None
    return False


def check_shifts(src, defines):
    found = []
    for m in re.finditer(r"(<<|>>)=?\s*\(?\s*(-?\s*(?:0x[0-9a-fA-F]+|\d+)|[A-Za-z_]\w*)", src.code):
        amount = m.group(2).replace(" ", "")
        if re.match(r"-?(?:0x|\d)", amount):
            value = int(amount, 0)
        elif amount in defines:
            value = defines[amount]
        else:
            continue
        if value >= 32 or value < 0:
            found.append((src.where(m.start()), "shift-amount", f"a shift by {amount} ({value})"))
    return found


def check_float_to_uint(src, types):
    found = []
    for m in re.finditer(r"\b(uint|uvec[234])\s*\(", src.code):
        end = matching(src.code, m.end() - 1)
        arg = src.code[m.end():end]
        if is_float_expr(arg, types) and not clamped_non_negative(arg):
            found.append((src.where(m.start()), "float-to-uint", f"{m.group(1)}({' '.join(arg.split())})"))
    return found


FUNCTION = re.compile(r"\b([A-Za-z_]\w*)\s+([A-Za-z_]\w*)\s*\(")


def functions(code):
    """(name, parameter text, body start, body end) of each function defined at the top level."""
    result = []
    depth = 0
    i = 0
    while i < len(code):
        ch = code[i]
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        elif depth == 0:
            m = FUNCTION.match(code, i)
            if m and m.group(1) not in ("return", "else", "layout", "struct", "uniform", "buffer"):
                close = matching(code, m.end() - 1)
                after = re.match(r"\s*\{", code[close + 1:])
                if after:
                    body_start = close + 1 + after.end() - 1
                    body_end = matching(code, body_start, "{", "}")
                    result.append((m.group(2), code[m.end():close], body_start, body_end))
                    i = body_end + 1
                    continue
                i = close + 1
                continue
        i += 1
    return result


def parameter_qualifiers(code):
    """function name -> list of 'out' / 'inout' / 'in' per parameter."""
    result = {}
    for name, params, _, _ in functions(code):
        quals = []
        depth, current = 0, ""
        for ch in params + ",":
            if ch == "," and depth == 0:
                words = current.strip()
                quals.append("inout" if re.match(r"(?:inout\b|PNANOVDB_INOUT\s*\()", words)
                             else "out" if re.match(r"out\b", words) else "in")
                current = ""
                continue
            depth += ch == "("
            depth -= ch == ")"
            current += ch
        result[name] = quals if params.strip() not in ("", "void") else []
    return result


def enclosing_call(body, pos):
    """(callee, argument index) of the call whose argument list holds `pos`, else None."""
    depth, commas = 0, 0
    for i in range(pos - 1, -1, -1):
        ch = body[i]
        if ch in ")]":
            depth += 1
        elif ch in "[":
            if depth == 0:
                return None
            depth -= 1
        elif ch == "(":
            if depth == 0:
                m = re.search(r"([A-Za-z_]\w*)\s*$", body[:i])
                return (m.group(1), commas) if m else None
            depth -= 1
        elif ch == "," and depth == 0:
            commas += 1
        elif ch in ";{}" and depth == 0:
            return None
    return None


DECLARATION = re.compile(r"(?:^|[;{}])\s*(?:const\s+)?(%s)\s+(\w+)\s*(?:\[[^\]]*\])?\s*;" %
                         "|".join(sorted(CHECKED_LOCAL_TYPES, key=len, reverse=True)))


def check_uninitialised(src, qualifiers):
    """(line, rule, message, function) of locals whose first use reads them."""
    found = []
    for fname, _, start, end in functions(src.code):
        body = src.code[start:end]
        for d in DECLARATION.finditer(body):
            name = d.group(2)
            use = re.compile(rf"\b{name}\b").search(body, d.end())
            if not use:
                continue
            rest = body[use.end():]
            if re.match(r"(?:\s*\.\s*\w+|\s*\[[^\]]*\])*\s*=(?!=)", rest):
                continue
            call = enclosing_call(body, use.start())
            if call and call[1] < len(qualifiers.get(call[0], [])) and qualifiers[call[0]][call[1]] == "out":
                continue
            found.append((src.where(start + use.start()), "uninitialised-read",
                          f"{d.group(1)} {name} is read before it is assigned", fname))
    return found


def check_root_walk(src):
    return [(src.where(m.start()), "pnanovdb-root-walk", f"{m.group(0).rstrip('(').strip()}(): PNanoVDB's root walk")
            for m in ROOT_WALK.finditer(src.code)]


def include_closure(root, rel, seen=None):
    """`rel` and every file it includes (transitively), as paths under `root` (vendor headers skipped)."""
    seen = set() if seen is None else seen
    if rel in seen or not (root / rel).is_file():
        return seen
    seen.add(rel)
    for inc in INCLUDE.findall((root / rel).read_text(encoding="utf-8", errors="replace")):
        include_closure(root, inc, seen)
    return seen


def variants(closure_text):
    """The define sets the host compiles this kernel with (gpu::Program defines)."""
    sets = [[]]
    if "TS_FP64" in closure_text:
        sets.append(["TS_FP64=1"])
    if "TS_CONTACT_SPRINGS" in closure_text:  # the contact kernel's specialisations (GpuStepper)
        lean = ["TS_CONTACT_SPRINGS=0", "TS_CONTACT_DAMPING=1", "TS_CONTACT_WALLS=0", "TS_CONTACT_PENETRATION=0"]
        sets += [lean, ["TS_FP64=1"] + lean, ["TS_FP64=1", "TS_CONTACT_FP64=1"]]
    if "TS_FIELD_CHUNKS" in closure_text:
        sets += [["TS_FIELD_CHUNKS=2", "TS_FIELD_CHUNK_SHIFT=25"], ["TS_FIELD_CHUNKS=8", "TS_FIELD_CHUNK_SHIFT=25"]]
    if "TS_PROBE_MODE" in closure_text:
        sets += [[f"TS_PROBE_MODE={m}"] for m in range(6)]
    return sets


def glslang_findings(root, jobs, glslang, nanovdb_include):
    """rel -> findings of glslangValidator over `jobs` ((rel, defines) pairs), run a few at a time."""
    def compile_one(job):
        rel, defines = job
        cmd = [glslang, "--quiet", "-G", "--auto-map-locations", "--auto-map-bindings", "-o", "/dev/null",
               "-S", KERNEL_STAGES[pathlib.Path(rel).suffix], f"-I{root}"]
        cmd += [f"-I{nanovdb_include}"] if nanovdb_include else []
        cmd += [f"-D{d}" for d in defines] + [str(root / rel)]
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode == 0:
            return rel, None
        errors = [l for l in (run.stdout + run.stderr).splitlines() if "ERROR" in l][:3]
        return rel, (1, "glslang", f"rejected with {' '.join(defines) or 'no defines'}: {' | '.join(errors)}")

    found = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
        for rel, finding in pool.map(compile_one, jobs):
            if finding:
                found.setdefault(rel, []).append(finding)
    return found


def audit_sources(root, glslang, nanovdb_include):
    """Findings in the shader tree under `root`: 'path:line: rule: message'."""
    files = sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.suffix in SOURCE_SUFFIXES)
    texts = {rel: (root / rel).read_text(encoding="utf-8", errors="replace") for rel in files}
    defines = {m.group(1): int(m.group(2), 0) for t in texts.values() for m in DEFINE_INT.finditer(t)}
    vendor = vendor_text(glslang, nanovdb_include)
    qualifiers = parameter_qualifiers(strip_comments("\n".join(texts.values()) + "\n" + (vendor or "")))
    closures = {rel: include_closure(root, rel) for rel in files}
    jobs = [(rel, defines) for rel in files if pathlib.Path(rel).suffix in KERNEL_STAGES
            for defines in variants("\n".join(texts[f] for f in closures[rel]))] if glslang else []
    compiled = glslang_findings(root, jobs, glslang, nanovdb_include)
    problems = []
    for rel in files:
        src = Source(rel, texts[rel])
        types = declared_types(strip_comments("\n".join(texts[f] for f in sorted(closures[rel]))))
        found = check_shifts(src, defines) + check_float_to_uint(src, types) + check_root_walk(src)
        found += [f[:3] for f in check_uninitialised(src, qualifiers)] + compiled.get(rel, [])
        problems += [f"{rel}:{line}: {rule}: {msg}" for line, rule, msg in found if not src.suppressed(line, rule)]
    if vendor is not None:
        problems += audit_vendor(vendor, defines, qualifiers)
    return problems, len(files)


def vendor_text(glslang, nanovdb_include):
    """PNanoVDB.h's GLSL branch, as glslang preprocesses it for the kernels (lines kept), or None."""
    if not glslang or not nanovdb_include or not (pathlib.Path(nanovdb_include) / "nanovdb/PNanoVDB.h").is_file():
        return None
    with tempfile.TemporaryDirectory() as tmp:
        wrapper = pathlib.Path(tmp) / "vendor.comp"
        wrapper.write_text('#version 450\n#extension GL_GOOGLE_include_directive : require\n'
                           'layout(local_size_x = 1) in;\n'
                           'layout(std430, binding = 0) readonly buffer B { uint pnanovdb_buf_data[]; };\n'
                           '#define PNANOVDB_GLSL\n#include "nanovdb/PNanoVDB.h"\nvoid main() {}\n')
        run = subprocess.run([glslang, "-E", f"-I{nanovdb_include}", str(wrapper)], capture_output=True, text=True)
    lines = run.stdout.split("\n")
    starts = [i for i, l in enumerate(lines) if l.startswith("#line 1 ") and "PNanoVDB.h" in l]
    if run.returncode != 0 or not starts:
        return None
    # Line n of the header is output line starts[0] + n: blank the wrapper so line numbers match the header.
    body = lines[starts[0] + 1:]
    return "\n".join(l if not l.startswith("#line") else "" for l in body)


def audit_vendor(text, defines, qualifiers):
    src = Source("nanovdb/PNanoVDB.h", text)
    types = declared_types(src.code)
    problems = []
    owners = functions(src.code)

    def owner(line):
        for name, _, start, end in owners:
            if src.where(start) <= line <= src.where(end):
                return name
        return ""

    found = [f + (owner(f[0]),) for f in check_shifts(src, defines) + check_float_to_uint(src, types)]
    found += check_uninitialised(src, qualifiers)
    for line, rule, msg, fname in found:
        if (rule, fname) not in KNOWN_VENDOR_FINDINGS:
            problems.append(f"nanovdb/PNanoVDB.h:{line} (GLSL branch, {fname}): {rule}: {msg}")
    return problems


PLANTED = {
    "common/planted_shift.glsl": "uint f(uint a) {\n  return a << 32u;\n}\n",
    "common/planted_define_shift.glsl": "#define TS_PLANTED_BITS 40\nuint g(uint a) {\n  return a >> TS_PLANTED_BITS;\n}\n",
    "common/planted_float.glsl": "uint h(vec3 p) {\n  float s = p.x - 1.0;\n  return uint(floor(s));\n}\n",
    "common/planted_member.glsl": "struct P { vec4 w; };\nuint k(P p) {\n  return uint(p.w.x * 2);\n}\n",
    "common/planted_uninit.glsl": "float u(float a) {\n  float x;\n  return a + x;\n}\n",
    "common/planted_inout.glsl": "void touch(inout int v) { v += 1; }\nint t() {\n  int n;\n  touch(n);\n  return n;\n}\n",
    "common/planted_walk.glsl": "uint r(ivec3 ijk) {\n  return pnanovdb_coord_to_key(ijk).x;\n}\n",
    "test/planted_variant.comp": "#version 450\nlayout(local_size_x = 1) in;\n#ifdef TS_FP64\nthis is not GLSL;\n"
                                  "#endif\nvoid main() {}\n",
}
CLEAN = {
    "common/clean.glsl": (
        "void fill(out float v) { v = 1.0; }\n"
        "uint a(vec3 p, int i, uint n) {\n"
        "  float x;\n  x = p.x;\n  float y;\n  fill(y);\n  float z[2];\n  z[0] = x;\n  z[1] = y;\n"
        "  uint c = uint(max(floor(p.y), 0.0)) + uint(clamp(p.z, 0.0, 4.0)) + uint(i) + (n << 31u) + (n >> 3);\n"
        "  // ts-audit: allow float-to-uint (p.x is a count the host writes, never negative)\n"
        "  return c + uint(x) + uint(z[0] + z[1]);\n}\n"),
    "test/clean.comp": "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n",
}
EXPECTED = [
    "common/planted_define_shift.glsl:3: shift-amount: a shift by TS_PLANTED_BITS (40)",
    "common/planted_float.glsl:3: float-to-uint: uint(floor(s))",
    "common/planted_inout.glsl:4: uninitialised-read: int n is read before it is assigned",
    "common/planted_member.glsl:3: float-to-uint: uint(p.w.x * 2)",
    "common/planted_shift.glsl:2: shift-amount: a shift by 32 (32)",
    "common/planted_uninit.glsl:3: uninitialised-read: float x is read before it is assigned",
    "common/planted_walk.glsl:2: pnanovdb-root-walk: pnanovdb_coord_to_key(): PNanoVDB's root walk",
]


def self_test(glslang, nanovdb_include):
    """Each rule catches the case planted for it in a throw-away tree, and the allowed forms pass."""
    with tempfile.TemporaryDirectory() as tmp:
        root = pathlib.Path(tmp)
        for rel, text in {**PLANTED, **CLEAN}.items():
            (root / rel).parent.mkdir(parents=True, exist_ok=True)
            (root / rel).write_text(text)
        problems, _ = audit_sources(root, glslang, None)
        glslang_found = [p for p in problems if ": glslang: " in p]
        other = sorted(p for p in problems if ": glslang: " not in p)
        ok = other == EXPECTED and len(glslang_found) == 1 and glslang_found[0].startswith(
            "test/planted_variant.comp:1: glslang: rejected with TS_FP64=1")
        if not ok:
            print("self-test failed:\n  found\n    " + "\n    ".join(problems) + "\n  expected\n    " +
                  "\n    ".join(EXPECTED + ["test/planted_variant.comp:1: glslang: rejected with TS_FP64=1 ..."]))
            return 1
        for rel in PLANTED:
            (root / rel).unlink()
        problems, _ = audit_sources(root, glslang, None)
        if problems:
            print("self-test failed: the clean tree was reported:\n  " + "\n  ".join(problems))
            return 1
    if nanovdb_include and vendor_text(glslang, nanovdb_include) is None:
        print(f"self-test failed: cannot preprocess nanovdb/PNanoVDB.h from {nanovdb_include}")
        return 1
    print(f"self-test passed: each of the {len(EXPECTED) + 1} planted cases was caught, the allowed forms passed")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("source_dir", nargs="?", default=".")
    parser.add_argument("--self-test", action="store_true")
    parser.add_argument("--glslang", default="/usr/bin/glslangValidator")
    parser.add_argument("--nanovdb-include", default="/usr/include")
    args = parser.parse_args()
    if not pathlib.Path(args.glslang).is_file():
        print(f"shader_audit: glslangValidator not found at {args.glslang}")
        return 1
    if args.self_test:
        return self_test(args.glslang, args.nanovdb_include)
    root = pathlib.Path(args.source_dir).resolve() / "shaders"
    if not root.is_dir():
        print(f"shader_audit: no shaders/ under {args.source_dir}")
        return 1
    problems, files = audit_sources(root, args.glslang, args.nanovdb_include)
    for p in problems:
        print(p)
    print(f"{files} shader files and PNanoVDB.h's GLSL branch checked: {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
