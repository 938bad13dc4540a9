#!/usr/bin/env python3
"""Counts the per-protocol match arms above the codec (issue 32).

usage: scripts/protocol-arms.py [--list]   (from the checkout to count)

Reads the non-test Rust code of hwfoc-records, hwfoc-ports, hwfoc-io, hwfoc-can-setup, hwfoc-web, hwfoc-cli, hwfoc-sim, hwfoc-bridge and python/src
(a file's `#[cfg(test)]` module, `tests.rs` files and `tests/` folders are left out) and finds each `match`
whose arms name an arm of a per-protocol enum (`Protocol`, `Data`, `Info`, `Fast`, `Decoded`,
`Family`, `Conversion`; until 2026-11-29 also the stream's `Wire` and `EscLink`, which were
per-protocol then: `Wire` is now a serial line's fast decoder or a `dyn LinkDecoder`, and
`LinkStats` a struct). It prints the number of such arms and of wildcard arms
(`_ =>`) in those matches: a wildcard absorbs a new protocol, so the compiler no longer names
the place. With --list, each wildcard's file and line.
"""

import pathlib
import re
import sys

ROOT = pathlib.Path.cwd()
DIRS = ["crates/hwfoc-records/src", "crates/hwfoc-ports/src", "crates/hwfoc-io/src",
        "crates/hwfoc-can-setup/src", "crates/hwfoc-web/src", "crates/hwfoc-cli/src", "crates/hwfoc-sim/src",
        "crates/hwfoc-bridge/src", "python/src"]
ENUMS = "Protocol|Data|Info|Fast|Decoded|Family|Conversion"
ARM = re.compile(r"(?<![\w:])(?:[\w]+::)*(?:" + ENUMS + r")::[A-Z]\w*")


def strip(text):
    """The text without comments, strings and chars (kept as spaces, so offsets hold)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"' or text.startswith('r#"', i):
            raw = c != '"'
            j = i + (3 if raw else 1)
            end = '"#' if raw else '"'
            while j < n and not text.startswith(end, j):
                j += 2 if (text[j] == "\\" and not raw) else 1
            j += len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:i + 4]):
            m = re.match(r"'(\\.|[^\\'])'", text[i:i + 4])
            out.append(" " * len(m.group(0)))
            i += len(m.group(0))
        else:
            out.append(c)
            i += 1
    return "".join(out)


def arms_of(body):
    """The arm patterns of a match body (the text between its braces)."""
    arms, depth, start = [], 0, 0
    i = 0
    while i < len(body):
        c = body[i]
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif depth == 0 and body.startswith("=>", i):
            arms.append((start, body[start:i].strip()))
            # skip the arm's expression: to the next top-level comma or block end
            j, d = i + 2, 0
            while j < len(body):
                if body[j] in "([{":
                    d += 1
                elif body[j] in ")]}":
                    d -= 1
                    if d == 0 and body[j] == "}" and body[i + 2:j + 1].strip().startswith("{"):
                        j += 1
                        break
                elif body[j] == "," and d == 0:
                    j += 1
                    break
                j += 1
            start = i = j
            continue
        i += 1
    return arms


def matches(code):
    """Each `match` in code: (offset of its body, body text)."""
    for m in re.finditer(r"\bmatch\b", code):
        i, depth = m.end(), 0
        while i < len(code):
            c = code[i]
            if c in "([":
                depth += 1
            elif c in ")]":
                depth -= 1
            elif c == "{" and depth == 0:
                break
            i += 1
        start, depth = i + 1, 1
        j = start
        while j < len(code) and depth:
            if code[j] == "{":
                depth += 1
            elif code[j] == "}":
                depth -= 1
            j += 1
        yield start, code[start:j - 1]


def main():
    listing = "--list" in sys.argv
    arms = wildcards = 0
    for d in DIRS:
        for path in sorted((ROOT / d).rglob("*.rs")):
            if "tests" in path.relative_to(ROOT / d).parts or path.name == "tests.rs":
                continue
            text = path.read_text()
            cut = re.search(r"#\[cfg\(test\)\]\s*(pub(\(crate\))? )?mod \w+", text)
            text = text if cut is None else text[:cut.start()]
            code = strip(text)
            for start, body in matches(code):
                found = arms_of(body)
                per_protocol = [p for _, p in found if ARM.search(p)]
                if not per_protocol:
                    continue
                arms += len(per_protocol)
                for offset, pattern in found:
                    if pattern == "_" or pattern.startswith("_ if"):
                        wildcards += 1
                        if listing:
                            line = code.count("\n", 0, start + offset) + 1
                            print(f"{path.relative_to(ROOT)}:{line}: _ =>")
    print(f"per-protocol arms above the codec: {arms}")
    print(f"wildcard arms in those matches: {wildcards}")


if __name__ == "__main__":
    main()
