#!/usr/bin/env python3
"""Import circles of the crate's module graph, checked against an allow-list.

usage: python3 scripts/import-circles.py [SRC_DIR] [--allow FILE] [--explain] [--edges]

Builds two kinds of module graphs from the `crate::`, `super::` and `self::` paths of every
source file under SRC_DIR (default `src`), leaving out code under `#[cfg(test)]`, comments
(doc comments included) and string literals:

- the top-level graph: one node per top-level module (`src/x.rs` or `src/x/`); an edge
  `a -> b` when code in `a` names an item that lives in `b`;
- for each top-level module directory `src/x/`, the graph of its child modules (`x::a`,
  `x::b`); the parent `x/mod.rs` is not a node (it declares and re-exports its children).

Names are followed through re-exports (`pub use`, and the private imports that child modules
see), so `crate::Result` is an edge to `error` and `super::Thing` re-exported by a `mod.rs`
is an edge to the child that defines `Thing`.

The strongly connected components with more than one module are the import circles. Each
circle must be one of the circles listed in the allow-list (default: `import-circles.allow`
beside this script; one circle a line, module names sorted and comma-separated, `#` starts a
comment) or a subset of one: a circle may shrink, it may not grow or appear. The exit status
is 1 when a circle is not allowed, 2 on a usage error, 0 otherwise.

--explain  for each circle found, its edges and the paths (file:line) that make them
--edges    every edge of every graph with the paths that make them
"""

import os
import re
import sys

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


# ---------------------------------------------------------------------------------------------
# Source text: comments, strings and `#[cfg(test)]` items blanked out (newlines kept, so that
# line numbers stay valid).


def blank(s):
    return re.sub(r"[^\n]", " ", s)


RAW_STRING = re.compile(r'b?r(#*)"')
CHAR_LITERAL = re.compile(r"'(?:\\(?:x[0-9a-fA-F]{2}|u\{[0-9a-fA-F]+\}|.)|[^\\'\n])'")


def strip_comments_and_strings(text):
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
            continue
        if text.startswith("/*", i):
            depth, j = 0, i
            while j < n:
                if text.startswith("/*", j):
                    depth += 1
                    j += 2
                elif text.startswith("*/", j):
                    depth -= 1
                    j += 2
                    if depth == 0:
                        break
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
            continue
        prev_ident = i > 0 and (text[i - 1].isalnum() or text[i - 1] == "_")
        m = RAW_STRING.match(text, i)
        if m and not prev_ident:
            end = '"' + m.group(1)
            j = text.find(end, m.end())
            j = n if j < 0 else j + len(end)
            out.append(blank(text[i:j]))
            i = j
            continue
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(blank(text[i:j]))
            i = j
            continue
        if c == "'":
            m = CHAR_LITERAL.match(text, i)
            if m:
                out.append(blank(m.group()))
                i = m.end()
                continue
        out.append(c)
        i += 1
    return "".join(out)


CFG_TEST = re.compile(r"#\s*\[\s*cfg\s*\(\s*(?:test|all\s*\(\s*test\b[^\]]*\))\s*\)\s*\]")
OPEN = "([{"
CLOSE = ")]}"


def skip_attribute(text, i):
    """`text[i]` is `#` of an attribute: the index after its closing `]`."""
    j = text.index("[", i)
    depth = 0
    while j < len(text):
        if text[j] == "[":
            depth += 1
        elif text[j] == "]":
            depth -= 1
            if depth == 0:
                return j + 1
        j += 1
    return len(text)


def item_end(text, i):
    """The index after the item starting at `i`: its `;` or its closing `}` at depth 0."""
    depth = 0
    j = i
    while j < len(text):
        ch = text[j]
        if ch in OPEN:
            depth += 1
        elif ch in CLOSE:
            depth -= 1
            if depth == 0 and ch == "}":
                return j + 1
        elif ch == ";" and depth == 0:
            return j + 1
        j += 1
    return len(text)


def strip_test_items(text):
    """Blanks every item under `#[cfg(test)]`; returns the text and the names of test-only
    out-of-line modules (`#[cfg(test)] mod name;`)."""
    test_modules = set()
    while True:
        m = CFG_TEST.search(text)
        if not m:
            return text, test_modules
        j = m.end()
        while True:
            while j < len(text) and text[j].isspace():
                j += 1
            if text.startswith("#", j):
                j = skip_attribute(text, j)
            else:
                break
        end = item_end(text, j)
        decl = re.match(r"(?:pub(?:\s*\([^)]*\))?\s+)?mod\s+(" + IDENT + r")\s*;", text[j:end])
        if decl:
            test_modules.add(decl.group(1))
        text = text[: m.start()] + blank(text[m.start() : end]) + text[end:]


# ---------------------------------------------------------------------------------------------
# Paths: `use` trees expanded, inline `crate::`/`super::`/`self::` paths.

USE = re.compile(r"(?<![A-Za-z0-9_$])use\s")
TOKEN = re.compile(r"::|[{},*]|\$?" + IDENT)


def expand_use_tree(tokens, pos, prefix, out):
    """Parses one use tree at `tokens[pos]`; appends each full path (list of segments) to
    `out` as (path, alias); returns the position after the tree."""
    path = list(prefix)
    while pos < len(tokens):
        tok = tokens[pos]
        if tok == "::":
            pos += 1
        elif tok == "{":
            pos += 1
            while pos < len(tokens) and tokens[pos] != "}":
                if tokens[pos] == ",":
                    pos += 1
                    continue
                pos = expand_use_tree(tokens, pos, path, out)
            return pos + 1
        elif tok == "*":
            if path:
                out.append((path, None))
            return pos + 1
        elif tok in (",", "}"):
            break
        elif tok == "as":
            alias = tokens[pos + 1] if pos + 1 < len(tokens) else None
            if path:
                out.append((path, alias))
            return pos + 2
        else:
            path.append(tok)
            pos += 1
    if path:
        if path[-1] == "self":
            path = path[:-1]
        if path:
            out.append((path, path[-1]))
    return pos


def use_statements(text):
    """Yields (start, end, [(path, alias)]) for each `use` declaration."""
    for m in USE.finditer(text):
        end = item_end(text, m.end())
        body = text[m.end() : end].rstrip(";")
        paths = []
        tokens = TOKEN.findall(body)
        pos = 0
        while pos < len(tokens):
            pos = expand_use_tree(tokens, pos, [], paths)
            if pos < len(tokens) and tokens[pos] in (",", "}"):
                pos += 1
        yield m.start(), end, paths


INLINE = re.compile(
    r"(?<![A-Za-z0-9_])(\$?crate|super|self)((?:\s*::\s*(?:" + IDENT + r"))+)"
)


def line_of(text, i):
    return text.count("\n", 0, i) + 1


# ---------------------------------------------------------------------------------------------
# The crate.


class Crate:
    def __init__(self, src):
        self.src = src
        self.files = {}  # relative path -> module path (tuple)
        for root, dirs, files in os.walk(src):
            dirs.sort()
            rel_root = os.path.relpath(root, src)
            parts = [] if rel_root == "." else rel_root.split(os.sep)
            if parts[:1] == ["bin"]:
                continue
            for f in sorted(files):
                if not f.endswith(".rs"):
                    continue
                name = f[:-3]
                if not parts and name in ("lib", "main"):
                    module = ()
                elif name == "mod":
                    module = tuple(parts)
                else:
                    module = tuple(parts + [name])
                self.files[os.path.join(*(parts + [f]))] = module
        self.modules = set(self.files.values())
        self.text = {}
        test_only = set()
        for rel, module in self.files.items():
            with open(os.path.join(src, rel), encoding="utf-8") as fh:
                text = strip_comments_and_strings(fh.read())
            text, test_modules = strip_test_items(text)
            self.text[rel] = text
            test_only |= {module + (t,) for t in test_modules}
        for rel, module in list(self.files.items()):
            if any(module[: len(t)] == t for t in test_only):
                del self.files[rel]
                del self.text[rel]
        self.modules = set(self.files.values())
        # Names brought into each module's scope by `use` (re-exports and private imports,
        # which child modules see too): module -> name -> absolute path.
        self.imports = {m: {} for m in self.modules}
        self.uses = {}  # rel -> [(line, absolute path, written)]
        for rel, module in self.files.items():
            text = self.text[rel]
            found = []
            for start, end, paths in use_statements(text):
                line = line_of(text, start)
                for path, alias in paths:
                    absolute = self.absolute(module, path, in_use=True)
                    if absolute is None:
                        continue
                    found.append((line, absolute, "::".join(path)))
                    if alias and alias != "_":
                        self.imports[module][alias] = absolute
                text = text[:start] + blank(text[start:end]) + text[end:]
            for m in INLINE.finditer(text):
                path = [m.group(1)] + re.findall(IDENT, m.group(2))
                absolute = self.absolute(module, path, in_use=False)
                if absolute is not None:
                    found.append((line_of(text, m.start()), absolute, "::".join(path)))
            self.uses[rel] = found

    def absolute(self, module, path, in_use):
        """The absolute path (tuple of segments) of `path` written in `module`, or None for
        paths outside the crate."""
        head = path[0]
        if head in ("crate", "$crate"):
            return tuple(path[1:])
        if head in ("super", "self"):
            base = list(module)
            rest = list(path)
            while rest and rest[0] in ("super", "self"):
                if rest[0] == "super":
                    if not base:
                        return None
                    base.pop()
                rest.pop(0)
            return tuple(base + rest)
        if in_use and module + (head,) in self.modules:
            return module + tuple(path)
        return None

    def resolve(self, path, depth=0):
        """The module in which the item named by the absolute `path` is defined."""
        current = ()
        for i, seg in enumerate(path):
            child = current + (seg,)
            if child in self.modules:
                current = child
                continue
            target = self.imports.get(current, {}).get(seg)
            if target is not None and depth < 32 and tuple(target) != current + (seg,):
                return self.resolve(tuple(target) + tuple(path[i + 1 :]), depth + 1)
            return current
        return current

    def graphs(self):
        """{graph name: {edge (a, b): [(file, line, written path)]}}; graph "" is the
        top level, graph "x" the children of top-level module x."""
        graphs = {"": {}}
        for m in self.modules:
            if len(m) == 1 and any(len(o) > 1 and o[0] == m[0] for o in self.modules):
                graphs[m[0]] = {}
        for rel, found in self.uses.items():
            module = self.files[rel]
            if not module:
                continue
            for line, absolute, written in found:
                target = self.resolve(absolute)
                cause = (rel, line, written)
                if target and target[0] != module[0]:
                    graphs[""].setdefault((module[0], target[0]), []).append(cause)
                if (
                    len(module) > 1
                    and len(target) > 1
                    and target[0] == module[0]
                    and target[1] != module[1]
                ):
                    a = module[0] + "::" + module[1]
                    b = target[0] + "::" + target[1]
                    graphs[module[0]].setdefault((a, b), []).append(cause)
        return graphs


def circles(edges):
    """Strongly connected components with more than one node (Tarjan, iterative)."""
    succ = {}
    for a, b in edges:
        succ.setdefault(a, set()).add(b)
        succ.setdefault(b, set())
    index, low, on_stack, stack, found = {}, {}, set(), [], []
    counter = 0
    for root in sorted(succ):
        if root in index:
            continue
        work = [(root, iter(sorted(succ[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(succ[w]))))
                    advanced = True
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    found.append(tuple(sorted(comp)))
    return sorted(found)


def read_allow(path):
    allowed = []
    with open(path, encoding="utf-8") as fh:
        for raw in fh:
            line = raw.split("#", 1)[0].strip()
            if line:
                allowed.append(frozenset(x.strip() for x in line.split(",") if x.strip()))
    return allowed


def print_causes(edges, comp, indent="  "):
    members = set(comp)
    for (a, b), causes in sorted(edges.items()):
        if a in members and b in members:
            print(f"{indent}{a} -> {b}")
            for rel, line, written in sorted(set(causes)):
                print(f"{indent}    {rel}:{line}: {written}")


def main(argv):
    args = list(argv)
    explain = "--explain" in args
    show_edges = "--edges" in args
    args = [a for a in args if a not in ("--explain", "--edges")]
    allow = os.path.join(os.path.dirname(os.path.abspath(__file__)), "import-circles.allow")
    if "--allow" in args:
        i = args.index("--allow")
        if i + 1 >= len(args):
            print(__doc__, file=sys.stderr)
            return 2
        allow = args[i + 1]
        del args[i : i + 2]
    if len(args) > 1 or any(a.startswith("-") for a in args):
        print(__doc__, file=sys.stderr)
        return 2
    src = args[0] if args else "src"
    if not os.path.isdir(src):
        print(f"import-circles: no directory {src}", file=sys.stderr)
        return 2
    allowed = read_allow(allow) if os.path.exists(allow) else []

    crate = Crate(src)
    graphs = crate.graphs()
    bad, shrunk = [], []
    n_circles = 0
    for name in sorted(graphs):
        edges = graphs[name]
        if show_edges:
            print(f"edges of {'the top level' if not name else name}:")
            for (a, b), causes in sorted(edges.items()):
                where = ", ".join(sorted({f"{r}:{l}" for r, l, _ in causes}))
                print(f"  {a} -> {b}   ({where})")
        for comp in circles(edges):
            n_circles += 1
            label = "circle" if not name else f"circle in {name}"
            ok = any(set(comp) <= a for a in allowed)
            print(f"{label}: {', '.join(comp)}{'' if ok else '   <- NOT ALLOWED'}")
            if explain or not ok:
                print_causes(edges, comp)
            if ok:
                if frozenset(comp) not in allowed:
                    shrunk.append(comp)
            else:
                bad.append(comp)
    for comp in shrunk:
        print(
            f"note: the circle {', '.join(comp)} is smaller than its allowed entry; "
            f"shrink {os.path.relpath(allow)} to it"
        )
    print(f"import circles: {n_circles} ({len(bad)} not allowed)")
    if bad:
        print(
            f"import-circles: new or grown import circles; the imports must point down the "
            f"layers (docs: DESIGN, third stage); {os.path.relpath(allow)} may only shrink",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
