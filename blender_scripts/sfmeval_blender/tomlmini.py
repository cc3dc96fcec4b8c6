"""A small TOML reader for Pythons without :mod:`tomllib` (Blender builds on Python 3.10).

It reads the subset sfmeval configs use: comments, ``[table]`` and ``[[array.of.tables]]``
headers, dotted and quoted keys, basic and literal strings, integers, floats, booleans,
(multi-line) arrays and inline tables. Anything else raises :class:`TomlError` with a line number.
Where :mod:`tomllib` exists, :func:`loads` uses it instead.
"""

import re

try:  # Python >= 3.11
    import tomllib as _tomllib
except ImportError:  # pragma: no cover - depends on the interpreter
    _tomllib = None


class TomlError(ValueError):
    pass


def loads(text, force_fallback=False):
    if _tomllib is not None and not force_fallback:
        try:
            return _tomllib.loads(text)
        except _tomllib.TOMLDecodeError as exc:
            raise TomlError(str(exc)) from None
    return _Parser(text).parse()


_BARE = re.compile(r"[A-Za-z0-9_-]+")
_NUM = re.compile(r"[+-]?(?:inf|nan|[0-9_]+(?:\.[0-9_]+)?(?:[eE][+-]?[0-9_]+)?|0x[0-9a-fA-F_]+)")
_ESC = {"b": "\b", "t": "\t", "n": "\n", "f": "\f", "r": "\r", '"': '"', "\\": "\\"}


class _Parser:
    def __init__(self, text):
        self.s = text.replace("\r\n", "\n")
        self.i = 0
        self.root = {}

    # -- helpers -------------------------------------------------------------------------
    def line(self):
        return self.s.count("\n", 0, self.i) + 1

    def err(self, msg):
        raise TomlError("line %d: %s" % (self.line(), msg))

    def peek(self):
        return self.s[self.i] if self.i < len(self.s) else ""

    def skip_ws(self, newlines=False):
        while self.i < len(self.s):
            c = self.s[self.i]
            if c in " \t" or (newlines and c == "\n"):
                self.i += 1
            elif c == "#":
                while self.i < len(self.s) and self.s[self.i] != "\n":
                    self.i += 1
            else:
                break

    def expect_eol(self):
        self.skip_ws()
        if self.i < len(self.s) and self.s[self.i] != "\n":
            self.err("unexpected text %r" % self.s[self.i:self.i + 20])

    # -- grammar -------------------------------------------------------------------------
    def parse(self):
        current = self.root
        while True:
            self.skip_ws(newlines=True)
            if self.i >= len(self.s):
                return self.root
            if self.s.startswith("[[", self.i):
                self.i += 2
                keys = self.key()
                self.skip_ws()
                if not self.s.startswith("]]", self.i):
                    self.err("expected ]]")
                self.i += 2
                parent = self.descend(self.root, keys[:-1])
                arr = parent.setdefault(keys[-1], [])
                if not isinstance(arr, list):
                    self.err("%s is not an array of tables" % ".".join(keys))
                current = {}
                arr.append(current)
            elif self.peek() == "[":
                self.i += 1
                keys = self.key()
                self.skip_ws()
                if self.peek() != "]":
                    self.err("expected ]")
                self.i += 1
                current = self.descend(self.root, keys)
            else:
                keys = self.key()
                self.skip_ws()
                if self.peek() != "=":
                    self.err("expected = after key")
                self.i += 1
                self.skip_ws()
                value = self.value()
                table = self.descend(current, keys[:-1])
                if keys[-1] in table:
                    self.err("duplicate key %s" % ".".join(keys))
                table[keys[-1]] = value
            self.expect_eol()

    def descend(self, table, keys):
        for k in keys:
            nxt = table.setdefault(k, {})
            if isinstance(nxt, list):
                if not nxt or not isinstance(nxt[-1], dict):
                    self.err("%s is not a table" % k)
                nxt = nxt[-1]
            elif not isinstance(nxt, dict):
                self.err("%s is not a table" % k)
            table = nxt
        return table

    def key(self):
        keys = []
        while True:
            self.skip_ws()
            c = self.peek()
            if c == '"':
                keys.append(self.basic_string())
            elif c == "'":
                keys.append(self.literal_string())
            else:
                m = _BARE.match(self.s, self.i)
                if not m:
                    self.err("expected a key")
                keys.append(m.group(0))
                self.i = m.end()
            self.skip_ws()
            if self.peek() == ".":
                self.i += 1
                continue
            return keys

    def value(self):
        c = self.peek()
        if self.s.startswith('"""', self.i) or self.s.startswith("'''", self.i):
            self.err("multi-line strings are not supported by the fallback TOML reader")
        if c == '"':
            return self.basic_string()
        if c == "'":
            return self.literal_string()
        if c == "[":
            return self.array()
        if c == "{":
            return self.inline_table()
        if self.s.startswith("true", self.i):
            self.i += 4
            return True
        if self.s.startswith("false", self.i):
            self.i += 5
            return False
        m = _NUM.match(self.s, self.i)
        if not m or not m.group(0):
            self.err("cannot read a value at %r" % self.s[self.i:self.i + 20])
        self.i = m.end()
        t = m.group(0).replace("_", "")
        if t.lstrip("+-").startswith("0x"):
            return int(t, 16)
        if re.fullmatch(r"[+-]?[0-9]+", t):
            return int(t)
        return float(t)

    def basic_string(self):
        self.i += 1
        out = []
        while True:
            if self.i >= len(self.s) or self.s[self.i] == "\n":
                self.err("unterminated string")
            c = self.s[self.i]
            self.i += 1
            if c == '"':
                return "".join(out)
            if c == "\\":
                e = self.s[self.i]
                self.i += 1
                if e in _ESC:
                    out.append(_ESC[e])
                elif e in "uU":
                    n = 4 if e == "u" else 8
                    out.append(chr(int(self.s[self.i:self.i + n], 16)))
                    self.i += n
                else:
                    self.err("bad escape \\%s" % e)
            else:
                out.append(c)

    def literal_string(self):
        j = self.s.find("'", self.i + 1)
        if j < 0 or "\n" in self.s[self.i:j]:
            self.err("unterminated string")
        v = self.s[self.i + 1:j]
        self.i = j + 1
        return v

    def array(self):
        self.i += 1
        out = []
        while True:
            self.skip_ws(newlines=True)
            if self.peek() == "]":
                self.i += 1
                return out
            out.append(self.value())
            self.skip_ws(newlines=True)
            if self.peek() == ",":
                self.i += 1
            elif self.peek() != "]":
                self.err("expected , or ] in array")

    def inline_table(self):
        self.i += 1
        out = {}
        self.skip_ws()
        if self.peek() == "}":
            self.i += 1
            return out
        while True:
            keys = self.key()
            if self.peek() != "=":
                self.err("expected = in inline table")
            self.i += 1
            self.skip_ws()
            self.descend(out, keys[:-1])[keys[-1]] = self.value()
            self.skip_ws()
            if self.peek() == ",":
                self.i += 1
            elif self.peek() == "}":
                self.i += 1
                return out
            else:
                self.err("expected , or } in inline table")
