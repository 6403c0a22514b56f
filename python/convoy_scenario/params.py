"""OpenSCENARIO parameters: declarations, scopes, references and expressions.

- A parameter is declared with a name, a type and a value. Types: ``integer`` (also ``int``,
  ``unsignedInt``, ``unsignedShort``), ``double``, ``string``, ``boolean`` (``true`` /
  ``false``) and ``dateTime`` (kept as its text). A declaration's value may itself be a
  reference or an expression over parameters declared before it.
- Scopes nest: the file's global declarations, then a Story's, a Maneuver's, a catalog
  entry's, a Trajectory's or Route's. A name is looked up from the innermost scope out. A
  catalog entry's declarations take the values of the reference's ParameterAssignments.
- A reference is a whole attribute value ``$name``; an expression (OpenSCENARIO 1.1) is a
  whole attribute value ``${...}`` over numbers, ``$name`` (integer or double parameters),
  ``+ - * / %``, unary minus and plus, parentheses and the functions ``round floor ceil
  sqrt pow``. It is parsed by recursive descent (never eval()) and gives a double; where an
  integer is wanted the result must be a whole number.
"""

import math
import re

INT_TYPES = ("integer", "int", "unsignedInt", "unsignedShort")
TYPES = INT_TYPES + ("double", "string", "boolean", "dateTime")
FUNCTIONS = {"round": (1, lambda a: float(math.floor(a + 0.5))),
             "floor": (1, lambda a: float(math.floor(a))),
             "ceil": (1, lambda a: float(math.ceil(a))),
             "sqrt": (1, None), "pow": (2, None)}


class ParameterError(Exception):
    """A bad reference, expression or value; the reader adds the file, line and attribute."""


class Scope:
    """Parameters visible at one place of the file: name -> (type, value), and the scope
    around it."""

    def __init__(self, parent=None):
        self.parent = parent
        self.values = {}

    def lookup(self, name):
        scope = self
        while scope is not None:
            if name in scope.values:
                return scope.values[name]
            scope = scope.parent
        raise ParameterError("unknown parameter $%s" % name)

    def flat(self):
        """Every visible parameter's value by name (inner scopes win)."""
        chain = []
        scope = self
        while scope is not None:
            chain.append(scope.values)
            scope = scope.parent
        out = {}
        for values in reversed(chain):
            out.update({k: v for k, (t, v) in values.items()})
        return out


def convert(value, ptype):
    """value (a string, or a number from an expression) as a parameter of type ptype."""
    if ptype in INT_TYPES:
        if isinstance(value, bool):
            raise ParameterError("expected an integer, got %r" % value)
        if isinstance(value, (int, float)):
            if float(value) != math.floor(float(value)) or not math.isfinite(float(value)):
                raise ParameterError("expected an integer, got %r" % value)
            out = int(value)
        else:
            try:
                out = int(value.strip())
            except ValueError:
                raise ParameterError("expected an integer, got %r" % value) from None
        if ptype != "integer" and ptype != "int" and out < 0:
            raise ParameterError("expected an unsigned integer, got %r" % value)
        return out
    if ptype == "double":
        if isinstance(value, bool):
            raise ParameterError("expected a number, got %r" % value)
        if isinstance(value, (int, float)):
            return float(value)
        try:
            out = float(value.strip())
        except ValueError:
            raise ParameterError("expected a number, got %r" % value) from None
        if not math.isfinite(out):
            raise ParameterError("expected a finite number, got %r" % value)
        return out
    if ptype == "boolean":
        if isinstance(value, bool):
            return value
        if isinstance(value, str) and value.strip() in ("true", "false"):
            return value.strip() == "true"
        raise ParameterError("expected true or false, got %r" % value)
    if ptype in ("string", "dateTime"):
        if isinstance(value, float) and value == math.floor(value):
            return str(int(value)) if abs(value) < 1e15 else repr(value)
        return str(value) if not isinstance(value, bool) else ("true" if value else "false")
    raise ParameterError("unknown parameterType %r (%s)" % (ptype, ", ".join(TYPES)))


def resolve(text, scope):
    """An attribute's value: a literal string, a parameter's typed value ($name) or an
    expression's double (${...})."""
    if text.startswith("${"):
        if not text.endswith("}"):
            raise ParameterError("expression %r has no closing }" % text)
        return evaluate(text[2:-1], scope)
    if text.startswith("$"):
        name = text[1:]
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name):
            raise ParameterError("bad parameter reference %r" % text)
        return scope.lookup(name)[1]
    return text


# --- expressions ---------------------------------------------------------------------------

_TOKEN = re.compile(r"\s*(?:(\d+\.?\d*(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?)"
                    r"|(\$[A-Za-z_][A-Za-z0-9_]*)|([A-Za-z_][A-Za-z0-9_]*)|([-+*/%(),]))")


def _tokens(source):
    pos = 0
    out = []
    source = source.rstrip()
    while pos < len(source):
        m = _TOKEN.match(source, pos)
        if not m or m.end() == pos:
            raise ParameterError("expression ${%s}: unexpected %r" % (source, source[pos:].strip()[:10]))
        number, param, name, op = m.groups()
        if number is not None:
            out.append(("num", float(number)))
        elif param is not None:
            out.append(("param", param[1:]))
        elif name is not None:
            out.append(("name", name))
        else:
            out.append(("op", op))
        pos = m.end()
    out.append(("end", None))
    return out


class _Text(str):
    """Text in an expression: esmini joins words and numbers with + (``${Name + _ + $n}``),
    which OpenSCENARIO's numeric expressions do not have; the result is a string. param:
    the string parameter it came from, if any."""
    param = None


def _param_text(name, value):
    t = _Text(value)
    t.param = name
    return t


CONSTANTS = {"pi": math.pi}   # esmini's expressions know pi


def _text(v):
    if isinstance(v, _Text):
        return str(v)
    return str(int(v)) if float(v) == math.floor(v) and abs(v) < 1e15 else repr(v)


def evaluate(source, scope):
    """The value (a float) of an OpenSCENARIO expression (without its ${ and })."""
    tokens = _tokens(source)
    pos = [0]

    def fail(msg):
        raise ParameterError("expression ${%s}: %s" % (source, msg))

    def peek():
        return tokens[pos[0]]

    def take():
        tok = tokens[pos[0]]
        pos[0] += 1
        return tok

    def expect(op):
        tok = take()
        if tok != ("op", op):
            fail("expected %r" % op)

    def expr():
        value = term()
        while peek() in (("op", "+"), ("op", "-")):
            op = take()[1]
            rhs = term()
            if isinstance(value, _Text) or isinstance(rhs, _Text):
                if op != "+":
                    fail("text can only be joined with +")
                value = _Text(_text(value) + _text(rhs))
            else:
                value = value + rhs if op == "+" else value - rhs
        return value

    def term():
        value = unary()
        while peek() in (("op", "*"), ("op", "/"), ("op", "%")):
            op = take()[1]
            rhs = unary()
            for v in (value, rhs):
                if isinstance(v, _Text):
                    fail("$%s is a string parameter, not a number" % v.param if v.param
                         else "%r needs numbers" % op)
            if op == "*":
                value = value * rhs
            elif rhs == 0:
                fail("division by zero")
            elif op == "/":
                value = value / rhs
            else:
                value = math.fmod(value, rhs)
        return value

    def unary():
        if peek() == ("op", "-"):
            take()
            operand = unary()
            if isinstance(operand, _Text):
                fail("'-' needs a number")
            return -operand
        if peek() == ("op", "+"):
            take()
            return unary()
        return primary()

    def primary():
        kind, val = take()
        if kind == "num":
            return val
        if kind == "param":
            try:
                ptype, value = scope.lookup(val)
            except ParameterError as e:
                fail(str(e))
            if ptype == "string":
                try:   # esmini: a string parameter holding a number is a number
                    return float(value)
                except ValueError:
                    return _param_text(val, value)
            if ptype not in INT_TYPES and ptype != "double":
                fail("$%s is a %s parameter, not a number" % (val, ptype))
            return float(value)
        if kind == "name":
            if val not in FUNCTIONS:
                if val in CONSTANTS and peek() != ("op", "("):
                    return CONSTANTS[val]
                if peek() != ("op", "("):
                    return _Text(val)   # a bare word: text (esmini's string expressions)
                fail("unknown function %r (%s)" % (val, ", ".join(FUNCTIONS)))
            expect("(")
            args = [expr()]
            while peek() == ("op", ","):
                take()
                args.append(expr())
            expect(")")
            arity, fn = FUNCTIONS[val]
            if len(args) != arity:
                fail("%s takes %d argument(s), got %d" % (val, arity, len(args)))
            if val == "sqrt":
                if args[0] < 0:
                    fail("sqrt of a negative number")
                return math.sqrt(args[0])
            if val == "pow":
                try:
                    out = math.pow(args[0], args[1])
                except (ValueError, OverflowError):
                    fail("pow(%g, %g) is undefined" % tuple(args))
                return out
            return fn(args[0])
        if (kind, val) == ("op", "("):
            value = expr()
            expect(")")
            return value
        fail("unexpected %s" % ("end" if kind == "end" else repr(val)))

    value = expr()
    if peek()[0] != "end":
        fail("unexpected %r" % (peek()[1],))
    if isinstance(value, _Text):
        return str(value)
    if not math.isfinite(value):
        fail("the value is not finite")
    return value
