#!/usr/bin/env python3
"""What the command line says about itself (app/cli_docs.h): --help wrapped to the terminal, the bash
completion script (parsed by bash and asked for words as bash would) and the man page (rendered by
groff without a warning).

  cli_docs_test.py TETRASAND_BINARY      exit 0 when every check holds
"""
import os
import shutil
import subprocess
import sys


def check(ok, what):
    if not ok:
        raise SystemExit(f"cli_docs_test: {what}")


def run(args, env=None):
    res = subprocess.run(args, capture_output=True, text=True, env=env)
    check(res.returncode == 0, f"{' '.join(args)} exits 0 (got {res.returncode}): {res.stderr[-400:]}")
    return res.stdout


def check_help(binary):
    env = dict(os.environ, COLUMNS="80")
    for command in ([], ["sim"], ["sample"], ["sdf"], ["preview"], ["export", "lammps"]):
        text = run([binary] + command + ["--help"], env)
        long = [l for l in text.splitlines() if len(l) > 80 and " " in l.strip()]
        check(not long, f"tetrasand {' '.join(command)} --help at 80 columns has {len(long)} longer lines: {long[:2]}")


def complete(script, words):
    """The words bash would offer after `words` (the last one being completed)."""
    line = " ".join(words)
    program = (f"source {script}\nCOMP_WORDS=({line})\nCOMP_CWORD={len(words) - 1}\n"
               "_tetrasand\nprintf '%s\\n' \"${COMPREPLY[@]}\"\n")
    return set(run(["bash", "-c", program]).split())


def check_completion(binary, work):
    script = os.path.join(work, "tetrasand.bash")
    open(script, "w").write(run([binary, "completion", "bash"]))
    run(["bash", "-n", script])
    check({"sdf", "sample", "sim", "export"} <= complete(script, ["tetrasand", "s"]) | complete(script, ["tetrasand", "e"]),
          "the subcommands are offered")
    check("--backend" in complete(script, ["tetrasand", "sim", "x.toml", "--ba"]), "sim's --backend is offered")
    check(complete(script, ["tetrasand", "sdf", "m.obj", "--backend", "''"]) == {"auto", "gpu", "cpu"},
          "--backend's values are offered")
    check("lammps" in complete(script, ["tetrasand", "export", "l"]), "export's lammps is offered")
    check("--json" in complete(script, ["tetrasand", "export", "lammps", "s.toml", "--j"]), "a nested command's options")


def check_man(binary, work):
    page = os.path.join(work, "tetrasand.1")
    open(page, "w").write(run([binary, "manpage"]))
    text = open(page).read()
    check(text.startswith(".TH TETRASAND 1"), "the man page starts with .TH")
    for command in ("sdf", "sample", "preview", "sim", "frames", "export lammps"):
        check(f'.SS "tetrasand {command}"' in text, f"the man page has tetrasand {command}")
    res = subprocess.run(["groff", "-man", "-Tutf8", "-ww", "-z", page], capture_output=True, text=True)
    check(res.returncode == 0 and not res.stderr.strip(), f"groff renders the page without a warning: {res.stderr[:400]}")


def main():
    binary = os.path.abspath(sys.argv[1])
    work = os.path.join(os.path.dirname(binary), "cli-docs-test")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    check_help(binary)
    check_completion(binary, work)
    check_man(binary, work)
    print("cli_docs_test: help wrapped, completion and man page made from the command line")


if __name__ == "__main__":
    main()
