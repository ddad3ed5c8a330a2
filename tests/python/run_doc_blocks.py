#!/usr/bin/env python3
"""Runs the ```python blocks of a Markdown file in order, in one namespace, from the current
folder (the repository root), and checks what each prints.

A block followed by a ```text block (nothing but blank lines between) must print exactly that
text; a block without one must print nothing. So every number a tutorial shows is what the
code gives. Exit 0 when all blocks ran and matched; 1 with the first difference otherwise.
The blocks run as the main module (__name__ == "__main__"), as in a script.

--as-script SCRIPT: instead, write the blocks one after another into the file SCRIPT and run it
as a script (`python3 SCRIPT`, this interpreter, in a new process, from the current folder,
within --timeout seconds): what a reader gets who copies the page into a file. It must print
every text block, in order, and exit 0 (a Dask example that starts worker processes would
import the script again in each, or wait forever, without its `if __name__ == "__main__":`).

    python3 tests/python/run_doc_blocks.py docs/python.md
    python3 tests/python/run_doc_blocks.py docs/python.md --as-script out/python_md.py
"""
import argparse
import contextlib
import io
import os
import re
import subprocess
import sys
import traceback

FENCE = re.compile(r"^```(\w*)\s*$")


def blocks(text):
    """(language, code, first line number) of every fenced block, in order."""
    out, lang, lines, start = [], None, [], 0
    for number, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if lang is None and m:
            lang, lines, start = m.group(1), [], number
        elif lang is not None and line.strip() == "```":
            out.append((lang, "\n".join(lines) + "\n", start))
            lang = None
        elif lang is not None:
            lines.append(line)
    return out


def main(path):
    found = blocks(open(path, encoding="utf-8").read())
    namespace = {"__name__": "__main__"}
    ran = 0
    for i, (lang, code, line) in enumerate(found):
        if lang != "python":
            continue
        expected = None
        if i + 1 < len(found) and found[i + 1][0] == "text":
            expected = found[i + 1][1]
        printed = io.StringIO()
        try:
            with contextlib.redirect_stdout(printed):
                exec(compile(code, f"{path}:{line}", "exec"), namespace)
        except Exception:  # the block's error, with its place in the file
            traceback.print_exc()
            print(f"{path}:{line}: the python block failed", file=sys.stderr)
            return 1
        ran += 1
        if (expected or "") != printed.getvalue():
            print(f"{path}:{line}: the python block printed\n{printed.getvalue()}"
                  f"the text block after it says\n{expected or ''}", file=sys.stderr)
            return 1
    if ran == 0:
        print(f"{path}: no python block", file=sys.stderr)
        return 1
    print(f"{path}: {ran} python blocks ran, their output as shown")
    return 0


def as_script(path, script, timeout):
    found = blocks(open(path, encoding="utf-8").read())
    code, expected = [], []
    for i, (lang, text, line) in enumerate(found):
        if lang != "python":
            continue
        code.append(f"# {path}:{line}\n{text}")
        if i + 1 < len(found) and found[i + 1][0] == "text":
            expected.append(found[i + 1][1])
    if not code:
        print(f"{path}: no python block", file=sys.stderr)
        return 1
    os.makedirs(os.path.dirname(os.path.abspath(script)), exist_ok=True)
    with open(script, "w", encoding="utf-8") as f:
        f.write("\n".join(code))
    try:
        run = subprocess.run([sys.executable, script], capture_output=True, text=True,
                             timeout=timeout)
    except subprocess.TimeoutExpired as e:
        print(f"{script}: still running after {timeout} s (a Dask example without its "
              f"`if __name__ == \"__main__\":`?)\n{e.stdout or ''}{e.stderr or ''}",
              file=sys.stderr)
        return 1
    if run.returncode != 0:
        print(f"{script}: exit {run.returncode}\n{run.stdout}{run.stderr}", file=sys.stderr)
        return 1
    if run.stdout != "".join(expected):
        print(f"{script} printed\n{run.stdout}the text blocks say\n{''.join(expected)}",
              file=sys.stderr)
        return 1
    print(f"{path}: {len(code)} python blocks ran as the script {script}, their output as shown")
    return 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("markdown")
    parser.add_argument("--as-script", metavar="SCRIPT")
    parser.add_argument("--timeout", type=float, default=900)
    args = parser.parse_args()
    if args.as_script:
        sys.exit(as_script(args.markdown, args.as_script, args.timeout))
    sys.exit(main(args.markdown))
