#!/usr/bin/env python3
"""Writes a translation unit that names every public name through the umbrella.

Collects the names the public headers (include/interpatch/**/*.hpp) declare at
namespace scope in namespace interpatch and its sub-namespaces (interpatch::io),
leaving out namespace detail: classes, structs, unions, enums, free functions
(templates included), type aliases and variables. The translation unit written to
OUTPUT includes only "interpatch/interpatch.hpp" and refers to each name with a
using-declaration (`using interpatch::coons;`), so it compiles only while the
umbrella declares every one of them.

Usage: public_names.py SOURCE_DIR OUTPUT
Fails (exit 1) when a header other than the two umbrellas yields no name: the
reader below would then have missed its declarations.
"""

import re
import sys
from pathlib import Path

UMBRELLAS = {"interpatch/interpatch.hpp", "interpatch/core.hpp"}
TYPE_KEYS = {"class", "struct", "union", "enum"}
KEYWORDS = {
    "alignas", "auto", "bool", "char", "class", "const", "consteval", "constexpr", "constinit", "decltype",
    "double", "enum", "explicit", "extern", "float", "friend", "inline", "int", "long", "noexcept", "operator",
    "short", "signed", "static", "struct", "template", "typename", "union", "unsigned", "using", "virtual",
    "void", "volatile",
}


def strip(text):
    """The text without comments, preprocessor lines, string and character literals."""
    text = re.sub(r"\\\n", " ", text)
    out = []
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = n if j < 0 else j + 2
            out.append(" ")
            continue
        m = re.match(r'R"([^(\s]*)\(', text[i:])
        if m:
            end = text.find(")" + m.group(1) + '"', i + m.end())
            i = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""')
            continue
        if c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            i = j + 1
            out.append('""')
            continue
        if c == "\n":
            at_line_start = True
        elif not c.isspace():
            at_line_start = False
        out.append(c)
        i += 1
    return "".join(out)


def tokens(text):
    return re.findall(r"[A-Za-z_]\w*|::|\d[\w.]*|\S", strip(text))


class Reader:
    def __init__(self, toks, header):
        self.t = toks
        self.i = 0
        self.header = header
        self.names = []  # (namespace, name)

    def peek(self):
        return self.t[self.i] if self.i < len(self.t) else None

    def skip_balanced(self, open_, close):
        """From an opening token to just past its match."""
        assert self.t[self.i] == open_
        depth = 0
        while self.i < len(self.t):
            tok = self.t[self.i]
            self.i += 1
            if tok == open_:
                depth += 1
            elif tok == close:
                depth -= 1
                if depth == 0:
                    return
        raise SystemExit(f"{self.header}: unbalanced {open_}{close}")

    def namespace_body(self, ns):
        """Statements up to the closing brace of namespace `ns` (or the end)."""
        while self.i < len(self.t):
            tok = self.peek()
            if tok == "}":
                self.i += 1
                return
            if tok == ";":
                self.i += 1
                continue
            if tok == "namespace" or (tok == "inline" and self.t[self.i + 1] == "namespace"):
                self.i += 2 if tok == "inline" else 1
                parts = []
                while self.peek() != "{":
                    if self.peek() not in ("::", "inline"):
                        parts.append(self.peek())
                    self.i += 1
                self.i += 1
                self.namespace_body(ns + tuple(parts or ["<anonymous>"]))
                continue
            self.statement(ns)

    def statement(self, ns):
        stmt = []
        kind = None  # what a '{' opens: a type's body, a function's body, or an initializer
        while self.i < len(self.t):
            tok = self.peek()
            if tok == "template" and not stmt:
                self.i += 1
                if self.peek() == "<":
                    depth = 0
                    while True:
                        tk = self.t[self.i]
                        self.i += 1
                        depth += tk == "<"
                        depth -= tk == ">"
                        if depth == 0:
                            break
                continue
            if tok in ("(", "["):
                # Parameters, arguments and attributes: only where they start matters.
                self.skip_balanced(tok, ")" if tok == "(" else "]")
                stmt.append(tok)
                continue
            if tok == ";":
                self.i += 1
                self.record(ns, stmt, body=False)
                return
            if tok == "{":
                self.record(ns, stmt, body=True)
                self.skip_balanced("{", "}")
                # A type or an initializer is followed by ';'; a function body is not.
                if self.declares_type(stmt) or "(" not in stmt or stmt.count("=") and stmt.index("=") < stmt.index("("):
                    while self.peek() not in (";", None):
                        self.i += 1
                    self.i += 1
                return
            stmt.append(tok)
            self.i += 1
        if stmt:
            raise SystemExit(f"{self.header}: declaration without an end: {' '.join(stmt)}")

    @staticmethod
    def declares_type(stmt):
        head = stmt[: stmt.index("(")] if "(" in stmt else stmt
        if "=" in head:
            head = head[: head.index("=")]
        return any(t in TYPE_KEYS for t in head) and "friend" not in head

    def record(self, ns, stmt, body):
        if not stmt:
            return
        name = None
        if stmt[0] == "using":
            if len(stmt) > 2 and stmt[1] != "namespace" and stmt[2] == "=":
                name = stmt[1]
        elif stmt[0] in ("static_assert", "friend"):
            return
        elif self.declares_type(stmt):
            k = next(j for j, t in enumerate(stmt) if t in TYPE_KEYS)
            k += 1
            while k < len(stmt) and (stmt[k] in ("class", "struct", "[") or stmt[k] in KEYWORDS):
                k += 1
            if k < len(stmt) and re.match(r"[A-Za-z_]\w*$", stmt[k]):
                name = stmt[k]
        elif "(" in stmt and not ("=" in stmt and stmt.index("=") < stmt.index("(")):
            if "operator" in stmt[: stmt.index("(")]:
                return
            before = stmt[stmt.index("(") - 1]
            if re.match(r"[A-Za-z_]\w*$", before) and before not in KEYWORDS:
                name = before
        else:
            cut = stmt.index("=") if "=" in stmt else len(stmt)
            idents = [t for t in stmt[:cut] if re.match(r"[A-Za-z_]\w*$", t) and t not in KEYWORDS]
            if idents:
                name = idents[-1]
        if name is None:
            raise SystemExit(f"{self.header}: cannot tell what this declares: {' '.join(stmt)}")
        if ns and ns[0] == "interpatch" and "detail" not in ns and "<anonymous>" not in ns:
            self.names.append(("::".join(ns), name))


def public_names(root):
    include = root / "include"
    found = {}
    for path in sorted((include / "interpatch").rglob("*.hpp")):
        header = path.relative_to(include).as_posix()
        if header in UMBRELLAS:
            continue
        reader = Reader(tokens(path.read_text(encoding="utf-8")), header)
        reader.namespace_body(())
        if not reader.names:
            raise SystemExit(f"{header}: no public name found; the reader in {Path(__file__).name} missed them")
        found[header] = reader.names
    return found


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    root, output = Path(sys.argv[1]), Path(sys.argv[2])
    found = public_names(root)
    by_namespace = {}
    for header, names in found.items():
        for ns, name in names:
            by_namespace.setdefault(ns, {}).setdefault(name, header)
    lines = [
        "// Generated by tests/headers/public_names.py: every public name the headers declare,",
        "// named through the umbrella header alone. It compiles only while",
        "// interpatch/interpatch.hpp declares each of them.",
        '#include "interpatch/interpatch.hpp"',
        "",
    ]
    for ns in sorted(by_namespace):
        lines.append(f"namespace names_of_{ns.replace('::', '_')} {{")
        for name, header in sorted(by_namespace[ns].items()):
            lines.append(f"using {ns}::{name};  // {header}")
        lines.append("}")
        lines.append("")
    text = "\n".join(lines)
    if not output.exists() or output.read_text(encoding="utf-8") != text:
        output.parent.mkdir(parents=True, exist_ok=True)
        output.write_text(text, encoding="utf-8")
    count = sum(len(v) for v in by_namespace.values())
    print(f"{count} public names from {len(found)} headers")
    return 0


if __name__ == "__main__":
    sys.exit(main())
