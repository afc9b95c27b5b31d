#!/usr/bin/env python3
"""Generates, from the LCM type definitions (lcmtypes/*.lcm), what the MCAP
export (scripts/lab export --mcap) needs to write a session's log as JSON:

  --header OUT.h     a C++17 header: for every type T, in namespace
                     rms::lcm_json, `nlohmann::ordered_json ToJson(const rms::T&)`
                     (every field by its name, in the .lcm's order; nested
                     types by their own ToJson; arrays as JSON arrays;
                     boolean as true/false; int8, byte and int64 as numbers).
                     It includes the lcm-gen classes as "rms/T.hpp".
  --schemas OUTDIR   OUTDIR/PACKAGE.T.json: a JSON Schema (draft-07) per type,
                     the MCAP channel schema (encoding "jsonschema") that
                     Foxglove Studio and PlotJuggler read: every field a
                     required property with its type and its .lcm comment as
                     "description"; nested types inlined; the constants in
                     the type's description.

  --limits OUT.h     a C++17 header: for every type T, in namespace
                     rms::lcm_limits, Bounds<rms::T>::kMaxEncodedSize (the
                     largest encoding of a message, fingerprint included) and
                     Bounds<rms::T>::Within(m) (every count and string within
                     its bound), from the bounds the .lcm declares: a const
                     MAX_X for each variable-length array sized by num_x (or
                     x), and MAX_F_BYTES for each string field f (its longest
                     text, bytes; per element in an array of strings). A
                     type whose bound is missing is an error naming it.

  gen_lcm_json.py --lcm-dir DIR [--header OUT.h] [--schemas OUTDIR] [--limits OUT.h]

Python 3, standard library only. Files whose contents would not change are
not rewritten (build tools see no new timestamps).
"""
import argparse
import json
import os
import re
import sys

PRIMITIVES = {
    # lcm type: (JSON Schema type, C++ element expression template, bounds)
    "int8_t": ("integer", "static_cast<int>({})", (-128, 127)),
    "int16_t": ("integer", "{}", (-32768, 32767)),
    "int32_t": ("integer", "{}", (-2147483648, 2147483647)),
    # int64: no bounds in the schema (a JSON reader's doubles can't hold them exactly).
    "int64_t": ("integer", "{}", None),
    "byte": ("integer", "static_cast<int>({})", (0, 255)),
    "float": ("number", "{}", None),
    "double": ("number", "{}", None),
    "string": ("string", "{}", None),
    "boolean": ("boolean", "({} != 0)", None),
}
INTEGER_TYPES = {"int8_t", "int16_t", "int32_t", "int64_t", "byte"}


class LcmError(Exception):
    pass


class Comment:
    def __init__(self, line, col, text, own_line, end_line=None):
        self.line, self.col, self.text, self.own_line = line, col, text, own_line
        self.end_line = end_line or line


class Token:
    def __init__(self, kind, text, line, col):
        self.kind, self.text, self.line, self.col = kind, text, line, col

    def __repr__(self):
        return f"{self.text!r}@{self.line}"


TOKEN_RE = re.compile(r"""
    (?P<ws>[ \t\r]+)
  | (?P<nl>\n)
  | (?P<line_comment>//[^\n]*)
  | (?P<block_comment>/\*.*?\*/)
  | (?P<number>[-+]?(?:0[xX][0-9a-fA-F]+|(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?))
  | (?P<ident>[A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)*)
  | (?P<punct>[{}\[\];=,])
""", re.S | re.X)


def tokenize(path, text):
    tokens, comments = [], []
    pos, line, line_start = 0, 1, 0
    line_has_token = False
    while pos < len(text):
        m = TOKEN_RE.match(text, pos)
        if not m:
            raise LcmError(f"{path}:{line}: unexpected character {text[pos]!r}")
        kind, value = m.lastgroup, m.group()
        col = pos - line_start
        if kind == "nl":
            line += 1
            line_start = m.end()
            line_has_token = False
        elif kind == "line_comment":
            comments.append(Comment(line, col, value[2:].strip(), not line_has_token))
        elif kind == "block_comment":
            body = value[2:-2]
            lines = [re.sub(r"^\s*\*?\s?", "", s).rstrip() for s in body.split("\n")]
            comments.append(Comment(line, col, "\n".join(lines).strip(), not line_has_token,
                                    line + value.count("\n")))
            line += value.count("\n")
            if "\n" in value:
                line_start = pos + value.rindex("\n") + 1
        elif kind != "ws":
            tokens.append(Token(kind, value, line, col))
            line_has_token = True
        pos = m.end()
    return tokens, comments


class Member:
    def __init__(self, type_name, name, dims, line, end_col):
        self.type_name = type_name   # "int32_t", "string", "rms.sender_t", ...
        self.name = name
        self.dims = dims             # list of ("fixed", int) or ("var", field name)
        self.line = line
        self.end_col = end_col       # column just past the member's ';'
        self.description = ""
        self.from_block = False      # description taken from the comment lines above


class Const:
    def __init__(self, type_name, name, value, line, end_col, statement):
        self.type_name, self.name, self.value = type_name, name, value
        self.line, self.end_col = line, end_col
        self.statement = statement   # consts declared together ("const int8_t A = 1, B = 2;")
        self.description = ""


class Struct:
    def __init__(self, package, name, path, line):
        self.package, self.name, self.path, self.line = package, name, path, line
        self.members, self.consts = [], []
        self.description = ""

    @property
    def full_name(self):
        return f"{self.package}.{self.name}" if self.package else self.name


def paragraphs(lines):
    """Comment lines to text: lines joined by spaces, an empty line a paragraph break."""
    out, cur = [], []
    for s in lines:
        if s.strip():
            cur.append(s.strip())
        elif cur:
            out.append(" ".join(cur))
            cur = []
    if cur:
        out.append(" ".join(cur))
    return "\n\n".join(out)


class Parser:
    def __init__(self, path, text):
        self.path = path
        self.tokens, self.comments = tokenize(path, text)
        self.i = 0
        self.used_comments = set()

    def error(self, msg, tok=None):
        tok = tok or (self.tokens[self.i] if self.i < len(self.tokens) else None)
        where = f"{self.path}:{tok.line}" if tok else f"{self.path}: at end of file"
        return LcmError(f"{where}: {msg}")

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def next(self, kind=None, text=None):
        tok = self.peek()
        if tok is None:
            raise self.error(f"expected {text or kind}, got end of file")
        if (kind and tok.kind != kind) or (text and tok.text != text):
            raise self.error(f"expected {text or kind}, got {tok.text!r}", tok)
        self.i += 1
        return tok

    def parse(self):
        package = ""
        structs = []
        while self.peek():
            tok = self.next("ident")
            if tok.text == "package":
                package = self.next("ident").text
                self.next(text=";")
            elif tok.text == "struct":
                structs.append(self.parse_struct(package, tok))
            elif tok.text == "enum":
                raise self.error("enum is not supported (lcm-gen deprecates it)", tok)
            else:
                raise self.error(f"expected 'package' or 'struct', got {tok.text!r}", tok)
        for s in structs:
            self.attach_comments(s)
        return structs

    def parse_struct(self, package, struct_tok):
        name = self.next("ident")
        s = Struct(package, name.text, self.path, struct_tok.line)
        self.next(text="{")
        while True:
            tok = self.peek()
            if tok is None:
                raise self.error(f"struct {s.name}: missing '}}'")
            if tok.text == "}":
                self.i += 1
                break
            if tok.text == "const":
                self.i += 1
                self.parse_const(s)
            else:
                self.parse_member(s)
        if self.peek() and self.peek().text == ";":
            self.i += 1
        if not s.members:
            raise self.error(f"struct {s.name} has no fields", struct_tok)
        return s

    def parse_const(self, s):
        statement = self.i
        type_tok = self.next("ident")
        if type_tok.text not in PRIMITIVES or type_tok.text in ("string", "boolean", "byte"):
            raise self.error(f"const of type {type_tok.text!r} is not allowed", type_tok)
        while True:
            name = self.next("ident")
            self.next(text="=")
            value_tok = self.next("number")
            text = value_tok.text
            try:
                value = int(text, 0) if type_tok.text in INTEGER_TYPES else float(text)
            except ValueError:
                raise self.error(f"const {name.text}: bad value {text!r} for {type_tok.text}", value_tok)
            sep = self.next("punct")
            s.consts.append(Const(type_tok.text, name.text, value, name.line, sep.col + 1, statement))
            if sep.text == ";":
                break
            if sep.text != ",":
                raise self.error(f"expected ',' or ';', got {sep.text!r}", sep)

    def parse_member(self, s):
        type_tok = self.next("ident")
        type_name = type_tok.text
        if type_name not in PRIMITIVES and "." not in type_name and s.package:
            type_name = f"{s.package}.{type_name}"
        while True:
            name = self.next("ident")
            dims = []
            while self.peek() and self.peek().text == "[":
                self.i += 1
                d = self.next()
                if d.kind == "number":
                    n = int(d.text, 0)
                    if n <= 0:
                        raise self.error(f"{name.text}: array size must be positive", d)
                    dims.append(("fixed", n))
                elif d.kind == "ident":
                    dims.append(("var", d.text))
                else:
                    raise self.error(f"{name.text}: bad array size {d.text!r}", d)
                self.next(text="]")
            sep = self.next("punct")
            if any(m.name == name.text for m in s.members):
                raise self.error(f"struct {s.name}: field {name.text} declared twice", name)
            for kind, d in dims:
                if kind == "var":
                    size = next((m for m in s.members if m.name == d), None)
                    if size is None or size.dims or size.type_name not in INTEGER_TYPES - {"byte"}:
                        raise self.error(f"{name.text}[{d}]: {d} must be an earlier integer field of {s.name}",
                                         name)
            s.members.append(Member(type_name, name.text, dims, name.line, sep.col + 1))
            if sep.text == ";":
                break
            if sep.text != ",":
                raise self.error(f"expected ',' or ';', got {sep.text!r}", sep)

    def attach_comments(self, s):
        by_line, by_end_line = {}, {}
        for idx, c in enumerate(self.comments):
            by_line.setdefault(c.line, []).append((idx, c))
            by_end_line.setdefault(c.end_line, []).append((idx, c))
        token_lines = {t.line for t in self.tokens}

        def trailing(line, end_col):
            """The comment after a declaration on its line, with its continuation
            lines (comment-only lines below it that start in the same column)."""
            for idx, c in by_line.get(line, []):
                if not c.own_line and c.col >= end_col and idx not in self.used_comments:
                    self.used_comments.add(idx)
                    parts, nxt = [c.text], line + 1
                    while nxt not in token_lines:
                        cont = [(i, k) for i, k in by_line.get(nxt, []) if k.own_line and k.col == c.col]
                        if not cont:
                            break
                        self.used_comments.add(cont[0][0])
                        parts.append(cont[0][1].text)
                        nxt += 1
                    return paragraphs(parts)
            return ""

        def above(line):
            """The comment lines just above a line (contiguous, no blank line)."""
            parts, prev = [], line - 1
            while prev >= 1 and prev not in token_lines:
                found = [(i, k) for i, k in by_end_line.get(prev, [])
                         if k.own_line and i not in self.used_comments]
                if not found:
                    break
                for i, k in found:
                    self.used_comments.add(i)
                parts[:0] = [k.text for _, k in found]
                prev = min(k.line for _, k in found) - 1
            return paragraphs([ln for p in parts for ln in p.split("\n")])

        # The struct's own comment, then every declaration in order (trailing
        # comments first, so that their continuation lines are not taken as
        # the comment above the next field).
        decls = sorted(s.members + s.consts, key=lambda d: (d.line, d.end_col))
        trail = {id(d): trailing(d.line, d.end_col) for d in decls}
        s.description = above(s.line)
        prev = None
        for d in decls:
            block = above(d.line)
            text = "\n\n".join(t for t in (block, trail[id(d)]) if t)
            if isinstance(d, Member):
                if text:
                    d.description, d.from_block = text, bool(block) and not trail[id(d)]
                elif isinstance(prev, Member) and prev.from_block and prev.line == d.line - 1:
                    # A comment above a group of fields with none of their own:
                    # "int64_t input_frame; int64_t input_send_time_us;".
                    d.description, d.from_block = prev.description, True
            else:
                d.description = text
            prev = d
        # Consts declared together share their comment.
        shared = {}
        for c in s.consts:
            if c.description:
                shared.setdefault(c.statement, c.description)
        for c in s.consts:
            c.description = c.description or shared.get(c.statement, "")


def load(lcm_dir):
    files = sorted(f for f in os.listdir(lcm_dir) if f.endswith(".lcm"))
    if not files:
        raise LcmError(f"{lcm_dir}: no .lcm files")
    types = {}
    for f in files:
        path = os.path.join(lcm_dir, f)
        with open(path, encoding="utf-8") as fh:
            for s in Parser(path, fh.read()).parse():
                if s.full_name in types:
                    raise LcmError(f"{path}:{s.line}: type {s.full_name} also defined in {types[s.full_name].path}")
                types[s.full_name] = s
    for s in types.values():
        for m in s.members:
            if m.type_name not in PRIMITIVES and m.type_name not in types:
                raise LcmError(f"{s.path}:{m.line}: {s.name}.{m.name}: unknown type {m.type_name}")

    # No type may contain itself (lcm-gen would reject it too).
    def check(name, stack):
        if name in stack:
            raise LcmError(f"{types[name].path}: type {name} contains itself: {' -> '.join(stack + [name])}")
        for m in types[name].members:
            if m.type_name in types:
                check(m.type_name, stack + [name])
    for name in types:
        check(name, [])
    return types


def format_value(v):
    return repr(v) if isinstance(v, float) else str(v)


def constants_description(s):
    if not s.consts:
        return ""
    lines = ["Constants:"]
    for c in s.consts:
        line = f"- {c.name} = {format_value(c.value)}"
        if c.description:
            line += f": {c.description}"
        lines.append(line)
    return "\n".join(lines)


def type_description(s):
    return "\n\n".join(t for t in (s.description, constants_description(s)) if t)


def type_schema(s, types, top):
    schema = {}
    if top:
        schema["$schema"] = "http://json-schema.org/draft-07/schema#"
    schema["title"] = s.full_name
    desc = type_description(s)
    if desc:
        schema["description"] = desc
    schema["type"] = "object"
    props = {}
    for m in s.members:
        if m.type_name in PRIMITIVES:
            json_type, _, bounds = PRIMITIVES[m.type_name]
            # A float or double that is not a number (NaN, infinite) is
            # written as null: JSON has no such number.
            elem = {"type": ["number", "null"]} if json_type == "number" else {"type": json_type}
            if bounds:
                elem["minimum"], elem["maximum"] = bounds
        else:
            elem = type_schema(types[m.type_name], types, False)
        for kind, d in reversed(m.dims):
            arr = {"type": "array", "items": elem}
            if kind == "fixed":
                arr["minItems"] = arr["maxItems"] = d
            elem = arr
        desc = m.description
        var = [d for kind, d in m.dims if kind == "var"]
        if var:
            note = "(" + " x ".join(str(d) for _, d in m.dims) + " elements)"
            desc = f"{desc} {note}" if desc else note
        if desc and m.type_name in types and not m.dims:
            # A nested type's own description gives way to the field's; its
            # constants stay (fields say "PROCESS_* below").
            desc = "\n\n".join(t for t in (desc, constants_description(types[m.type_name])) if t)
        prop = {"description": desc} if desc else {}
        for k, v in elem.items():
            if k != "description" or not desc:
                prop[k] = v
        props[m.name] = prop
    schema["properties"] = props
    schema["required"] = [m.name for m in s.members]
    schema["additionalProperties"] = False
    return schema


def cpp_type(full_name):
    return "::" + full_name.replace(".", "::")


def member_code(m):
    if m.type_name in PRIMITIVES:
        elem = PRIMITIVES[m.type_name][1]
    else:
        elem = "ToJson({})"
    if not m.dims:
        return [f'  j["{m.name}"] = {elem.format("m." + m.name)};']
    lines = ["  {"]
    depth = len(m.dims)
    lines.append("    nlohmann::ordered_json a0 = nlohmann::ordered_json::array();")
    src = f"m.{m.name}"
    indent = "    "
    for k in range(depth):
        lines.append(f"{indent}for (const auto& e{k} : {src}) {{")
        indent += "  "
        if k + 1 < depth:
            lines.append(f"{indent}nlohmann::ordered_json a{k + 1} = nlohmann::ordered_json::array();")
        src = f"e{k}"
    lines.append(f"{indent}a{depth - 1}.push_back({elem.format(f'e{depth - 1}')});")
    for k in reversed(range(depth)):
        indent = indent[:-2]
        lines.append(f"{indent}}}")
        if k > 0:
            lines.append(f"{indent}a{k - 1}.push_back(std::move(a{k}));")
    lines.append(f'    j["{m.name}"] = std::move(a0);')
    lines.append("  }")
    return lines


def header(types):
    names = sorted(types)
    out = [
        "// Generated by lcmtypes/gen_lcm_json.py from lcmtypes/*.lcm: do not edit.",
        "// rms::lcm_json::ToJson(message) for every LCM type: every field by its name,",
        "// in the .lcm's order, as the type's JSON Schema (PACKAGE.T.json) describes it.",
        "// A string must be UTF-8 for nlohmann::json's dump() (or dump with",
        "// error_handler_t::replace); a non-finite float or double dumps as null.",
        "#pragma once",
        "",
        "#include <utility>",
        "",
        "#include <nlohmann/json.hpp>",
        "",
    ]
    out += [f'#include "{n.replace(".", "/")}.hpp"' for n in names]
    out += ["", "namespace rms::lcm_json {", ""]
    out += [f"inline nlohmann::ordered_json ToJson(const {cpp_type(n)}& m);" for n in names]
    for n in names:
        s = types[n]
        out += ["", f"// {n}", f"inline nlohmann::ordered_json ToJson(const {cpp_type(n)}& m) {{",
                "  nlohmann::ordered_json j = nlohmann::ordered_json::object();"]
        for m in s.members:
            out += member_code(m)
        out += ["  return j;", "}"]
    out += ["", "}  // namespace rms::lcm_json", ""]
    return "\n".join(out)


SIZES = {"int8_t": 1, "byte": 1, "boolean": 1, "int16_t": 2, "int32_t": 4, "float": 4, "int64_t": 8, "double": 8}


def bound_name(dim):
    return "MAX_" + (dim[4:] if dim.startswith("num_") else dim).upper()


def const_value(s, name, what):
    for c in s.consts:
        if c.name == name:
            if not isinstance(c.value, int) or c.value < 0:
                raise LcmError(f"{s.full_name}: {name} must be a non-negative integer ({what})")
            return c.value
    raise LcmError(f"{s.full_name}: {what} needs a bound: declare 'const int32_t {name} = N;'")


def max_size(s, types):
    """The largest encoding of s's fields (no fingerprint), bytes."""
    total = 0
    for m in s.members:
        count = 1
        for kind, d in m.dims:
            count *= d if kind == "fixed" else const_value(s, bound_name(d), f"the array {m.name}[{d}]")
        if m.type_name == "string":
            elem = 4 + const_value(s, f"MAX_{m.name.upper()}_BYTES", f"the string {m.name}") + 1
        elif m.type_name in SIZES:
            elem = SIZES[m.type_name]
        else:
            elem = max_size(types[m.type_name], types)
        total += count * elem
    return total


def fixed_size(s, types):
    """True when every encoding of s has the same size: no string and no
    variable-length array in it or in a type it holds."""
    for m in s.members:
        if m.type_name == "string" or any(kind != "fixed" for kind, _ in m.dims):
            return False
        if m.type_name in types and not fixed_size(types[m.type_name], types):
            return False
    return True


def within_code(s, types, var):
    """C++ conditions: every count and string of `var` (a T) within its bound."""
    conds, counted = [], set()
    t = cpp_type(s.full_name)
    for m in s.members:
        for kind, d in m.dims:
            if kind == "var" and d not in counted:
                counted.add(d)
                conds.append(f"{var}.{d} >= 0 && {var}.{d} <= {t}::{bound_name(d)}")
        if m.type_name == "string":
            limit = f"{t}::MAX_{m.name.upper()}_BYTES"
            if m.dims:
                conds.append(f"std::all_of({var}.{m.name}.begin(), {var}.{m.name}.end(), "
                             f"[](const std::string& e) {{ return e.size() <= {limit}; }})")
            else:
                conds.append(f"{var}.{m.name}.size() <= {limit}")
        elif m.type_name in types and not m.dims:
            conds.append(f"Bounds<{cpp_type(m.type_name)}>::Within({var}.{m.name})")
    return conds


def nested_first(types):
    """Type names, each after the types it contains (an explicit
    specialization must be declared before another's body uses it)."""
    order, seen = [], set()

    def visit(n):
        if n in seen:
            return
        seen.add(n)
        for m in types[n].members:
            if m.type_name in types:
                visit(m.type_name)
        order.append(n)
    for n in sorted(types):
        visit(n)
    return order


def limits_header(types):
    names = nested_first(types)
    out = [
        "// Generated by lcmtypes/gen_lcm_json.py from lcmtypes/*.lcm: do not edit.",
        "// The bounds of every LCM type, from the bounds its .lcm declares (MAX_X",
        "// for a variable-length array, MAX_F_BYTES for a string): the largest",
        "// encoding of a message, fingerprint included, and whether a decoded",
        "// message keeps within them. rms::wire::SafeDecode refuses a larger",
        "// message before decoding it and one out of bounds after (docs/protocol.md",
        "// \"Malformed messages\"). kFixedSize: every encoding of the type has",
        "// kMaxEncodedSize bytes (no string, no variable-length array).",
        "#pragma once",
        "",
        "#include <algorithm>",
        "#include <string>",
        "",
    ]
    out += [f'#include "{n.replace(".", "/")}.hpp"' for n in names]
    out += ["", "namespace rms::lcm_limits {", "", "template <class T>", "struct Bounds;"]
    for n in names:
        s = types[n]
        conds = within_code(s, types, "m")
        body = " &&\n           ".join(conds) if conds else "true"
        out += ["", "template <>", f"struct Bounds<{cpp_type(n)}> {{",
                f"  static constexpr int kMaxEncodedSize = {8 + max_size(s, types)};",
                f"  static constexpr bool kFixedSize = {'true' if fixed_size(s, types) else 'false'};",
                f"  static bool Within([[maybe_unused]] const {cpp_type(n)}& m) {{",
                f"    return {body};", "  }", "};"]
    out += ["", "// The largest encoding of a T, bytes, fingerprint included.", "template <class T>",
            "inline constexpr int kMaxEncodedSize = Bounds<T>::kMaxEncodedSize;", "",
            "}  // namespace rms::lcm_limits", ""]
    return "\n".join(out)


def write_if_changed(path, text):
    try:
        with open(path, encoding="utf-8") as fh:
            if fh.read() == text:
                return False
    except FileNotFoundError:
        pass
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
    os.replace(tmp, path)
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lcm-dir", required=True, help="folder of the .lcm files")
    ap.add_argument("--header", help="the C++ header to write (ToJson)")
    ap.add_argument("--schemas", help="the folder to write PACKAGE.T.json into")
    ap.add_argument("--limits", help="the C++ header to write (Bounds, kMaxEncodedSize)")
    args = ap.parse_args()
    if not args.header and not args.schemas and not args.limits:
        ap.error("nothing to do: give --header and/or --schemas")
    try:
        types = load(args.lcm_dir)
    except (LcmError, OSError) as e:
        print(f"gen_lcm_json: {e}", file=sys.stderr)
        return 1
    if args.header:
        d = os.path.dirname(os.path.abspath(args.header))
        os.makedirs(d, exist_ok=True)
        write_if_changed(args.header, header(types))
    if args.limits:
        try:
            text = limits_header(types)
        except LcmError as e:
            print(f"gen_lcm_json: {e}", file=sys.stderr)
            return 1
        os.makedirs(os.path.dirname(os.path.abspath(args.limits)), exist_ok=True)
        write_if_changed(args.limits, text)
    if args.schemas:
        os.makedirs(args.schemas, exist_ok=True)
        for n, s in sorted(types.items()):
            text = json.dumps(type_schema(s, types, True), indent=2, ensure_ascii=False) + "\n"
            write_if_changed(os.path.join(args.schemas, f"{n}.json"), text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
