"""C++ functional nodes (NRP-Core 1.4's FN factory modules).

build_fn_factory_module.sh HEADER [g++ options] (this module's main()) reads the functions a
header declares or defines,

    bool name(const In1* i1, ..., Out1& o1, ...);     inputs first, then outputs

generates a C++ file that includes the header and, with _fn_factory_runtime.h, exposes each
function to Python, and compiles it with g++ into libFNFactoryModule.so in the current folder
(boost.python, so the header may use boost::python::object as NRP-Core's do).

createFNFromFactoryModule(module_name, function_name, node_name, exec_policy) loads the
module and returns a functional node (CppFunctionalNode) that runs the function as NRP-Core's
FunctionalNode does: an input with no value is a null pointer; outputs are default-constructed
once and kept by the node between calls; the outputs are sent only when it returns true.
"""
import ctypes
import os
import re
import subprocess
import sys
import sysconfig
from collections import namedtuple

from . import _graph
from ._functional import FunctionalNode
from ._policies import ON_NEW_MESSAGE, ComputationalGraphError

MODULE_FILE = "libFNFactoryModule.so"
BUILD_DIR = ".build_fn_factory_module"
RUNTIME_HEADER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_fn_factory_runtime.h")

Function = namedtuple("Function", "name line inputs outputs")  # ports: [(name, type)]


class FactoryModuleError(Exception):
    """A header that cannot be parsed or compiled: the message names the header and line."""


# ------------------------------------------------------------------------------ the header

def _blank(text):
    """`text` with comments, string and character literals and preprocessor lines turned
    into spaces (newlines kept, so offsets keep their line numbers)."""
    out = list(text)
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#":
            j = i
            while j < n and (text[j] != "\n" or text[j - 1] == "\\"):
                j += 1
            for k in range(i, j):
                if out[k] != "\n":
                    out[k] = " "
            i = j
            continue
        if c in " \t":
            i += 1
            continue
        line_start = c == "\n"
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            if c == "\"":  # keep the quotes: extern "C" stays recognisable
                for k in range(i + 1, j - 1):
                    out[k] = "\n" if text[k] == "\n" else " "
                i = j
                continue
        else:
            i += 1
            continue
        for k in range(i, j):
            if out[k] != "\n":
                out[k] = " "
        i = j
    return "".join(out)


def _split_top(text, sep=","):
    parts, depth, start = [], 0, 0
    for i, c in enumerate(text):
        if c in "<([{":
            depth += 1
        elif c in ">)]}":
            depth -= 1
        elif c == sep and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return parts


_SPECIFIERS = {"static", "inline", "extern", "constexpr", "[[nodiscard]]"}
_KEYWORDS = {"const", "volatile", "unsigned", "signed", "int", "long", "short", "char", "bool",
             "float", "double", "void", "auto", "struct", "class", "typename"}


def _parse_param(text, where, fname):
    text = _split_top(text, "=")[0].strip()
    m = re.search(r"([A-Za-z_]\w*)\s*$", text)
    if not m or m.group(1) in _KEYWORDS or not text[:m.start()].strip():
        raise FactoryModuleError('%s: can\'t process function "%s": all function parameters '
                                 "must be named (\"%s\")" % (where, fname, " ".join(text.split())))
    name = m.group(1)
    ctype = " ".join(text[:m.start()].split())
    ctype = re.sub(r"\s*([*&<>,:])\s*", r"\1", ctype).replace(",", ", ")
    ctype = re.sub(r"(?<=[\w>])([*&])", r" \1", ctype)
    im = re.match(r"^(?:const\s+(.+?)|(.+?)\s+const)\s*\*(?:\s*const)?$", ctype)
    if im:
        return name, "in", (im.group(1) or im.group(2)).strip()
    om = re.match(r"^(.+?)\s*&$", ctype)
    if om and not ctype.endswith("&&") and not re.match(r"^const\b|.*\bconst$", om.group(1)):
        return name, "out", om.group(1).strip()
    raise FactoryModuleError('%s: can\'t process function "%s": parameter "%s" is a "%s". '
                             "Function parameters must be 0 or more input parameters (const T*) "
                             "followed by 0 or more output parameters (T&)"
                             % (where, fname, name, ctype))


def _function(stmt, line, header):
    """The Function a top-level statement declares, None for any other statement."""
    flat = " ".join(stmt.split())
    p = flat.find("(")
    if p < 0 or "=" in flat[:p]:
        return None
    m = re.search(r"([A-Za-z_][\w:]*)\s*$", flat[:p])
    if not m:
        return None
    prefix = re.sub(r'\bextern\s*"\s*"', "", flat[:m.start()]).strip()
    name = m.group(1)
    if not prefix or re.search(r"\b(template|typedef|using|operator|friend)\b", flat) or \
            name in _KEYWORDS:
        return None  # a macro's use, a template, an alias...
    depth, q = 0, p
    for q in range(p, len(flat)):
        depth += {"(": 1, ")": -1}.get(flat[q], 0)
        if depth == 0:
            break
    rest = flat[q + 1:].strip()
    if depth or not re.fullmatch(r"(noexcept(\s*\(\s*\w*\s*\))?|throw\s*\(\s*\))?", rest):
        return None  # e.g. a variable initialised by a constructor call
    where = "%s:%d" % (header, line)
    words = [w for w in prefix.split() if w not in _SPECIFIERS]
    if words != ["bool"]:
        raise FactoryModuleError('%s: can\'t process function "%s". Return type must be "bool" '
                                 '(it is "%s")' % (where, name, " ".join(words)))
    params = flat[p + 1:q].strip()
    inputs, outputs = [], []
    if params and params != "void":
        for text in _split_top(params):
            pname, kind, ctype = _parse_param(text, where, name)
            if kind == "in" and outputs:
                raise FactoryModuleError(
                    '%s: can\'t process function "%s": input "%s" after an output. Function '
                    "parameters must be 0 or more input parameters (const T*) followed by 0 or "
                    "more output parameters (T&)" % (where, name, pname))
            (inputs if kind == "in" else outputs).append((pname, ctype))
    return Function(name, line, inputs, outputs)


def parse_header(path):
    """The functions of header `path` (top level and namespaces; class bodies, templates and
    other statements are skipped), as NRP-Core's generateFNFactoryModule takes them."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            text = _blank(f.read())
    except OSError as e:
        raise FactoryModuleError("File [%s] can't be read: %s" % (path, e.strerror)) from None
    header = os.path.basename(path)
    functions, seen = [], {}
    stack = []  # one entry per open brace: namespace name, or None (a body: skipped)
    stmt_start = 0
    for i, c in enumerate(text):
        if c not in "{};":
            continue
        top = all(s is not None for s in stack)
        stmt = text[stmt_start:i]
        line = text.count("\n", 0, stmt_start + len(stmt) - len(stmt.lstrip())) + 1
        if c == "}":
            if stack:
                stack.pop()
            stmt_start = i + 1
            continue
        if top:
            flat = " ".join(stmt.split())
            ns = re.fullmatch(r"(?:inline\s+)?namespace(?:\s+([\w:]+))?|extern\s+\"\s*\"", flat)
            fn = None if ns else _function(stmt, line, header)
            if fn is not None:
                qualified = "::".join([s for s in stack if s] + [fn.name])
                fn = fn._replace(name=qualified)
                if qualified in seen and seen[qualified] != (fn.inputs, fn.outputs):
                    raise FactoryModuleError('%s:%d: function "%s" is overloaded: each function '
                                             "of an FN factory module needs its own name"
                                             % (header, line, qualified))
                if qualified not in seen:
                    seen[qualified] = (fn.inputs, fn.outputs)
                    functions.append(fn)
            if c == "{":
                stack.append((ns.group(1) or "") if ns else None)
        elif c == "{":
            stack.append(None)
        stmt_start = i + 1
    return functions


# ------------------------------------------------------------------------------ the module

def _c_str(s):
    return '"%s"' % s.replace("\\", "\\\\").replace('"', '\\"')


def generate(header_path, functions):
    """The C++ source of the module (a `#line` before each function's entry, so that a
    compiler error about it names the header's line)."""
    header_path = os.path.abspath(header_path)
    lines = ["// Generated by build_fn_factory_module.sh from %s. Do not edit." % header_path,
             "#include <boost/python.hpp>",
             "#include %s" % _c_str(header_path),
             "#include %s" % _c_str(RUNTIME_HEADER),
             "",
             'extern "C" __attribute__((visibility("default"))) PyObject* '
             "convoy_fn_factory_module() {",
             "  namespace cf = convoy_fn_factory;",
             "  try {",
             "    boost::python::dict m;"]
    for fn in functions:
        def names(ports):
            return "{%s}" % ", ".join(_c_str(p[0]) for p in ports)

        def types(ports):
            return "{%s}" % ", ".join(_c_str(p[1]) for p in ports)
        ins = ", ".join(t for _, t in fn.inputs)
        outs = ", ".join(t for _, t in fn.outputs)
        lines.append("#line %d %s" % (fn.line, _c_str(header_path)))
        lines.append("    m[%s] = cf::Entry<std::tuple<%s>, std::tuple<%s>>::make({&%s, %s, %s, "
                     "%s, %s, %s});" % (_c_str(fn.name), ins, outs, fn.name, _c_str(fn.name),
                                        names(fn.inputs), types(fn.inputs), names(fn.outputs),
                                        types(fn.outputs)))
    lines += ["    return boost::python::incref(m.ptr());",
              "  } catch (const boost::python::error_already_set&) {",
              "    return nullptr;",
              "  }",
              "}", ""]
    return "\n".join(lines)


def _compiler_command(source, output, extra):
    cxx = os.environ.get("CXX", "g++").split()
    version = "%d%d" % sys.version_info[:2]
    return cxx + ["-std=c++17", "-O2", "-fPIC", "-shared", "-o", output, source,
                  "-I" + sysconfig.get_paths()["include"]] + list(extra) + \
        ["-lboost_python" + version]


def build(header, out_dir=".", extra=(), log=print):
    """Builds `out_dir`/libFNFactoryModule.so from `header`; returns its path. Raises
    FactoryModuleError naming the header (and line) on failure."""
    if not os.path.isfile(header):
        raise FactoryModuleError("File [%s] can't be found" % header)
    functions = parse_header(header)
    if not functions:
        raise FactoryModuleError("%s: no function found: an FN factory module needs functions "
                                 "like bool f(const T* in..., U& out...)" % header)
    log("Generating module from file: %s (%s)" % (header, ", ".join(f.name for f in functions)))
    work = os.path.join(out_dir, BUILD_DIR)
    os.makedirs(work, exist_ok=True)
    source = os.path.join(work, "fn_factory_module.cpp")
    with open(source, "w") as f:
        f.write(generate(header, functions))
    final = os.path.join(out_dir, MODULE_FILE)
    temp = final + ".tmp%d" % os.getpid()
    extra = list(extra) + ["-I" + os.path.dirname(os.path.abspath(header))]
    cmd = _compiler_command(source, temp, extra)
    try:
        r = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        raise FactoryModuleError("%s: cannot run the compiler %s: %s"
                                 % (header, cmd[0], e.strerror)) from None
    if r.returncode != 0:
        if os.path.exists(temp):
            os.unlink(temp)
        hint = ""
        if "boost_python" in r.stderr and "cannot find" in r.stderr or \
                "boost/python.hpp" in r.stderr:
            hint = "\n(boost.python is needed: apt-get install libboost-python-dev)"
        raise FactoryModuleError("%s: compiling the FN factory module failed (%s):\n%s%s"
                                 % (header, " ".join(cmd), r.stderr.rstrip(), hint))
    os.replace(temp, final)
    return final


# --------------------------------------------------------------------------- loading, nodes

class FactoryModule:
    """A loaded libFNFactoryModule.so: function name -> its callable and ports."""

    def __init__(self, path):
        self.path = path
        try:
            lib = ctypes.PyDLL(path)
            entry = lib.convoy_fn_factory_module
        except (OSError, AttributeError) as e:
            raise ComputationalGraphError('Plugin Library "%s" could not be loaded: %s. Build it '
                                          "with build_fn_factory_module.sh HEADER" % (path, e)) \
                from None
        entry.restype = ctypes.py_object
        entry.argtypes = []
        self._lib = lib  # kept: the functions live in it
        self.functions = dict(entry())


_loaded = {}  # real path -> FactoryModule, in load order


def _find(module_name, caller_dir):
    if os.path.dirname(module_name):
        candidates = [module_name]
    else:
        dirs = [caller_dir, os.getcwd()] + \
            [d for d in os.environ.get("LD_LIBRARY_PATH", "").split(os.pathsep) if d]
        candidates = [os.path.join(d, module_name) for d in dirs if d]
    for c in candidates:
        if os.path.isfile(c):
            return os.path.realpath(c)
    raise ComputationalGraphError('Plugin Library "%s" could not be loaded: not found in %s. '
                                  "Build it in the experiment's folder with "
                                  "build_fn_factory_module.sh HEADER"
                                  % (module_name, ", ".join(sorted(set(
                                      os.path.dirname(c) or "." for c in candidates)))))


def load_module(module_name, caller_dir=None):
    path = _find(module_name, caller_dir)
    module = _loaded.get(path)
    if module is None:
        module = _loaded[path] = FactoryModule(path)
    return module


class CppFunctionalNode(FunctionalNode):
    """A functional node whose body is a C++ function of an FN factory module."""

    type_str = "CppFunctionalNode"

    def __init__(self, node_name, function_name, module, entry, exec_policy=ON_NEW_MESSAGE):
        call, in_names, in_types, out_names, out_types, ids = entry
        FunctionalNode.__init__(self, node_name, list(out_names), exec_policy)
        self.function = call
        self.function_name = function_name
        self.module_path = module.path
        self.inputs = list(in_names)
        self._in_types = dict(zip(in_names, in_types))
        self._out_types = dict(zip(out_names, out_types))
        self._in_ids = dict(zip(in_names, ids[0]))
        self._out_ids = dict(zip(out_names, ids[1]))
        self._out_values = [None] * len(out_names)
        self.__name__ = function_name

    def port_type(self, port, is_input):
        """(C++ type id, type as written) of an input or output port."""
        if is_input:
            return self._in_ids[port], self._in_types[port]
        return self._out_ids[port], self._out_types[port]

    def __call__(self, function):
        raise ComputationalGraphError('Functional node "%s" is made from C++ function "%s": it '
                                      "cannot decorate a Python function" % (self.id,
                                                                            self.function_name))

    def _run(self):
        ins = tuple(self._values.get(k) for k in self.inputs)
        try:
            ok = self.function(ins, self._out_values)
        except Exception as e:
            raise ComputationalGraphError('An error occurred while executing Functional Node with '
                                          'id "%s" (C++ function "%s" of %s): %s: %s'
                                          % (self.id, self.function_name, self.module_path,
                                             type(e).__name__, e)) from e
        return list(self._out_values) if ok else None


def create_node(module_name, function_name, node_name, exec_policy, caller_dir=None):
    for what, value in (("module_name", module_name), ("function_name", function_name),
                        ("node_name", node_name)):
        if not isinstance(value, str):
            raise TypeError("createFNFromFactoryModule: %s must be a string, got %r"
                            % (what, value))
    module = load_module(module_name, caller_dir)
    # As NRP-Core: the named module first, then every module loaded before.
    for m in [module] + [m for m in _loaded.values() if m is not module]:
        if function_name in m.functions:
            node = CppFunctionalNode(node_name, function_name, m, m.functions[function_name],
                                     exec_policy)
            _graph.current().register_node(node)
            return node
    raise ComputationalGraphError('Failed to instantiate Functional Node "%s" from function "%s" '
                                  "after trying with all loaded plugins (%s has: %s)"
                                  % (node_name, function_name, module.path,
                                     ", ".join(sorted(module.functions)) or "no function"))


def main(argv=None):
    """build_fn_factory_module.sh HEADER [g++ options]"""
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print("Usage: build_fn_factory_module.sh HEADER_FILE_PATH [g++ options]\n"
              "Builds libFNFactoryModule.so in the current folder from the functions of the "
              "header:\n  bool name(const In* in..., Out& out...)", file=sys.stderr)
        return 1 if not argv else 0
    try:
        path = build(argv[0], ".", argv[1:])
    except FactoryModuleError as e:
        print("build_fn_factory_module.sh: error: %s" % e, file=sys.stderr)
        return 1
    print("Built %s" % path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
