"""C++ functional nodes (createFNFromFactoryModule, build_fn_factory_module.sh): NRP-Core's
cpp_nodes_simple example, unchanged, run by Convoy's Python EventLoop; the function semantics
(null inputs, outputs kept between calls, false sends nothing, C++ values between C++ nodes);
the header's errors by file and line. Each class builds its module once (g++, a few s)."""
import contextlib
import io
import logging
import os
import shutil
import tempfile
import textwrap
import unittest

from nrp_core.event_loop import (ComputationalGraphError, EventLoop, load_computational_graph)
from nrp_core.event_loop import _factory_module as fm

logging.getLogger("nrp_core.event_loop").setLevel(logging.ERROR)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLE = os.path.join(REPO, "experiments", "nrp_event_loop", "cpp_nodes_simple")
NRP_EXAMPLE = "/tmp/nrpsrc/examples/event_loop_examples/cpp_nodes_simple"

SEMANTICS_H = r"""
#include <boost/python.hpp>
#include <string>
#include <vector>

namespace bp = boost::python;
struct Pose { double x = 0; int visits = 0; };   // a C++ type with no Python conversion

namespace demo {
// counts its calls in an output: outputs are kept between calls
bool counter(const bp::object* tick, int& count, bp::object& report) {
    count += 1;
    report = bp::make_tuple(count, tick == nullptr ? bp::object("null") : *tick);
    return true;
}
}

/* an odd value: no outputs this cycle */
bool even_only(const int* v, int& out) {
    if (v == nullptr || *v % 2) return false;
    out = *v;
    return true;
}

bool make_pose(const boost::python::object* x, Pose& pose) {
    if (x == nullptr) return false;
    pose.x = bp::extract<double>(*x);
    pose.visits += 1;
    return true;
}

bool read_pose(const Pose* pose, std::vector<double>& xs, boost::python::object& o) {
    if (pose == nullptr) return false;
    xs = {pose->x, double(pose->visits)};
    o = boost::python::object(pose->visits);
    return true;
}

bool scale(const double* x, double& y) { y = x ? 2 * *x : -1; return true; }
"""


def build_into(directory, header_text, name="nodes.h"):
    path = os.path.join(directory, name)
    with open(path, "w") as f:
        f.write(header_text)
    return fm.build(path, directory, log=lambda *_: None)


class CppNodesSimple(unittest.TestCase):
    """experiments/nrp_event_loop/cpp_nodes_simple, files unchanged, built into a temp
    folder and run for some cycles by the Python EventLoop."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        for name in ("fn.py", "test.h", "simulation_config.json"):
            shutil.copy(os.path.join(EXAMPLE, name), cls.tmp.name)
        fm.build(os.path.join(cls.tmp.name, "test.h"), cls.tmp.name, log=lambda *_: None)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_files_unchanged(self):
        if not os.path.isdir(NRP_EXAMPLE):
            self.skipTest("NRP-Core's sources are not at /tmp/nrpsrc")
        for name in ("fn.py", "test.h", "simulation_config.json"):
            with open(os.path.join(EXAMPLE, name), "rb") as a, \
                    open(os.path.join(NRP_EXAMPLE, name), "rb") as b:
                self.assertEqual(a.read(), b.read(), name)

    def test_header_functions(self):
        fns = {f.name: f for f in fm.parse_header(os.path.join(EXAMPLE, "test.h"))}
        self.assertEqual(sorted(fns), ["from_python", "print_python_int", "to_python"])
        self.assertEqual(fns["from_python"].inputs, [("i1", "boost::python::object")])
        self.assertEqual(fns["from_python"].outputs, [("o1", "int")])
        self.assertEqual(fns["to_python"].inputs, [("i1", "int")])
        self.assertEqual(fns["print_python_int"].outputs, [])
        self.assertEqual(fns["from_python"].line, 8)

    def test_var_x_increments(self):
        graph = load_computational_graph(["fn.py"], "AllNodes", None, self.tmp.name)
        g = graph.nodes["py_node_1"].function.__globals__
        self.assertEqual([type(graph.nodes[n]).__name__ for n in ("cpp_node_1", "cpp_node_2")],
                         ["CppFunctionalNode"] * 2)
        # py_node_1 -> cpp_node_1 -> cpp_node_2 -> py_node_2: one layer each
        self.assertEqual([[n.id for n in layer] for layer in graph.functional_layers],
                         [["py_node_1"], ["cpp_node_1"], ["cpp_node_2"], ["py_node_2"]])
        loop = EventLoop(graph, timestep=0.1)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            for cycle in range(10):
                self.assertEqual(g["var_x"], cycle)
                loop.run_once(cycle * 100)
        self.assertEqual(g["var_x"], 10)
        # what NRP-Core prints: py_node_2's print(i1), 0 to 9
        self.assertEqual(out.getvalue().split(), [str(i) for i in range(10)])

    def test_run_with_timeout(self):
        graph = load_computational_graph(["fn.py"], "AllNodes", None, self.tmp.name)
        loop = EventLoop(graph, timestep=0.1)
        with contextlib.redirect_stdout(io.StringIO()):
            loop.run(timeout=0.35)
        g = graph.nodes["py_node_1"].function.__globals__
        self.assertEqual(g["var_x"], loop.iterations)
        self.assertGreaterEqual(loop.iterations, 3)

    def test_python_value_into_int_input(self):
        """from_python gets a str: boost's extract fails, it prints and returns false."""
        graph = load_computational_graph(["fn.py"], "AllNodes", None, self.tmp.name)
        g = graph.nodes["py_node_1"].function.__globals__
        g["var_x"] = "seven"
        with contextlib.redirect_stdout(io.StringIO()):
            EventLoop(graph).run_once(0)
        self.assertEqual(g["var_x"], "seven")  # nothing went past cpp_node_1


class NrpCoreEdgeExamples(unittest.TestCase):
    """NRP-Core's own test graphs nrp_event_loop/tests/examples/fn_to_fn_edges (C++ -> C++,
    C++ -> Python, Python -> C++, Python -> Python), read from NRP-Core's sources when they
    are at /tmp/nrpsrc: the dummy's 10 reaches the output dummy every cycle."""

    SRC = "/tmp/nrpsrc/nrp_event_loop/tests/examples/fn_to_fn_edges"

    @classmethod
    def setUpClass(cls):
        if not os.path.isdir(cls.SRC):
            raise unittest.SkipTest("NRP-Core's sources are not at /tmp/nrpsrc")
        cls.tmp = tempfile.TemporaryDirectory()
        for name in os.listdir(cls.SRC):
            shutil.copy(os.path.join(cls.SRC, name), cls.tmp.name)
        fm.build(os.path.join(cls.tmp.name, "test.h"), cls.tmp.name, log=lambda *_: None)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_all_four(self):
        import json
        for kind in ("cpp2cpp", "cpp2py", "py2cpp", "py2py"):
            with open(os.path.join(self.tmp.name, kind + "_config.json")) as f:
                files = json.load(f)["ComputationalGraph"]
            graph = load_computational_graph(files, "AllNodes", None, self.tmp.name)
            loop = EventLoop(graph)
            with contextlib.redirect_stdout(io.StringIO()):
                for i in range(3):
                    loop.run_once(i)
            sent = [n.sent for n in graph.nodes.values() if hasattr(n, "sent")]
            self.assertEqual(sent, [[10, 10, 10]], kind)


class Semantics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        build_into(cls.tmp.name, SEMANTICS_H)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def load(self, source):
        path = os.path.join(self.tmp.name, "cg.py")
        with open(path, "w") as f:
            f.write("from nrp_core.event_loop import *\n" + textwrap.dedent(source))
        return load_computational_graph(["cg.py"], "AllNodes", None, self.tmp.name)

    def test_null_input_and_kept_outputs(self):
        graph = self.load("""
            always = node_policies.functional_node.exec_policy.always
            fn = createFNFromFactoryModule("libFNFactoryModule.so", "demo::counter", "cnt", always)
            @FromFunctionalNode("report", "/cnt/report")
            @FunctionalNode(name="sink", outputs=[])
            def sink(report):
                got.append(report)
            got = []
            """)
        loop = EventLoop(graph)
        for i in range(3):
            loop.run_once(i)
        got = graph.nodes["sink"].function.__globals__["got"]
        self.assertEqual(got, [(1, "null"), (2, "null"), (3, "null")])

    def test_false_sends_nothing(self):
        """counter's count (1, 2, 3, 4) into even_only: odd counts return false, so its
        output node gets only the even ones."""
        graph = self.load("""
            always = node_policies.functional_node.exec_policy.always
            cnt = createFNFromFactoryModule("libFNFactoryModule.so", "demo::counter", "cnt",
                                            always)
            ev = createFNFromFactoryModule("libFNFactoryModule.so", "even_only", "even",
                                           node_policies.functional_node.exec_policy.on_new_message)
            FromFunctionalNode("v", "/cnt/count")(ev)
            OutputDummy("out", "/sent")(ev)
            """)
        loop = EventLoop(graph)
        for i in range(4):
            loop.run_once(i)
        self.assertEqual(graph.nodes["/sent"].sent, [2, 4])

    def test_type_mismatch_between_nodes(self):
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r"'read'.*port 'pose'.*port 'out' of node 'even'.*"
                                    r"int and Pose"):
            self.load("""
                p = node_policies.functional_node.exec_policy.on_new_message
                a = createFNFromFactoryModule("libFNFactoryModule.so", "even_only", "even", p)
                b = createFNFromFactoryModule("libFNFactoryModule.so", "read_pose", "read", p)
                FromFunctionalNode("pose", "/even/out")(b)
                """)

    def test_cpp_value_between_cpp_nodes(self):
        """A Pose goes from make_pose to read_pose as C++ (kept by make_pose between calls:
        visits counts), with no Python conversion; read_pose's vector and object come out as
        Python values. At iteration 1 src sends nothing: the C++ nodes (on_new_message) do
        not run and the sink (always) keeps its input."""
        graph = self.load("""
            p = node_policies.functional_node.exec_policy.on_new_message
            @Iteration("it")
            @FunctionalNode(name="src", outputs=["x"])
            def src(it):
                return None if it == 1 else [it * 0.5]
            mk = createFNFromFactoryModule("libFNFactoryModule.so", "make_pose", "mk", p)
            FromFunctionalNode("x", "/src/x")(mk)
            rd = createFNFromFactoryModule("libFNFactoryModule.so", "read_pose", "rd", p)
            FromFunctionalNode("pose", "/mk/pose")(rd)
            OutputDummy("xs", "/xs")(rd)
            @FromFunctionalNode("o", "/rd/o")
            @FunctionalNode(name="sink", outputs=[],
                            exec_policy=node_policies.functional_node.exec_policy.always)
            def sink(o):
                got.append(o)
            got = []
            """)
        loop = EventLoop(graph)
        for i in range(4):
            loop.run_once(i)
        self.assertEqual(graph.nodes["sink"].function.__globals__["got"], [1, 1, 2, 3])
        self.assertEqual(graph.nodes["/xs"].sent, [[0.0, 1.0], [1.0, 2.0], [1.5, 3.0]])

    def test_bad_value_names_node_and_port(self):
        """A typed input fed by an input node gets the value converted; a str is an error
        naming the node, the function, the port and the types."""
        graph = self.load("""
            fn = createFNFromFactoryModule("libFNFactoryModule.so", "scale", "sc",
                                           node_policies.functional_node.exec_policy.always)
            InputDummy("x", "/num", 1.5)(fn)
            OutputDummy("y", "/y")(fn)
            """)
        loop = EventLoop(graph)
        loop.run_once(0)
        self.assertEqual(graph.nodes["/y"].sent, [3.0])
        graph.nodes["/num"].value = "text"
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r'"sc" \(C\+\+ function "scale".*input "x" of C\+\+ '
                                    r'function "scale" takes a double, got a Python str'):
            loop.run_once(1)

    def test_type_check_python_to_int(self):
        """NRP-Core's rule: a Python node's output (a boost::python::object) cannot feed a
        C++ int input."""
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r"'even'.*port 'v'.*port 'x' of node 'src'.*"
                                    r"boost::python::object and int"):
            self.load("""
                @Iteration("it")
                @FunctionalNode(name="src", outputs=["x"])
                def src(it):
                    return [it]
                fn = createFNFromFactoryModule("libFNFactoryModule.so", "even_only", "even",
                                               node_policies.functional_node.exec_policy.always)
                FromFunctionalNode("v", "/src/x")(fn)
                """)

    def test_unknown_function_and_module(self):
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r'from function "nope".*has: demo::counter, even_only'):
            self.load("""
                createFNFromFactoryModule("libFNFactoryModule.so", "nope", "n",
                                          node_policies.functional_node.exec_policy.always)
                """)
        with self.assertRaisesRegex(ComputationalGraphError, r'"libOther.so" could not be loaded'):
            self.load("""
                createFNFromFactoryModule("libOther.so", "even_only", "n",
                                          node_policies.functional_node.exec_policy.always)
                """)


class HeaderErrors(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def fails(self, text, pattern):
        with self.assertRaisesRegex(fm.FactoryModuleError, pattern):
            build_into(self.tmp.name, text)
        self.assertFalse(os.path.exists(os.path.join(self.tmp.name, fm.MODULE_FILE)))

    def test_signature_errors_name_header_and_line(self):
        self.fails("\n\nint f(const int* a, int& b);\n",
                   r'nodes.h:3: can\'t process function "f". Return type must be "bool"')
        self.fails("bool f(int& b,\n  const int* a);\n", r'nodes.h:1: .*input "a" after an output')
        self.fails("// x\nbool f(const int*, int& b);\n", r"nodes.h:2: .*must be named")
        self.fails("bool f(int a);\n", r'nodes.h:1: .*parameter "a" is a "int"')
        self.fails("bool f(const int& a);\n", r'parameter "a" is a "const int &"')
        self.fails("struct S { int x; };\n", r"no function found")

    def test_skipped_statements(self):
        path = os.path.join(self.tmp.name, "ok.h")
        with open(path, "w") as f:
            f.write(textwrap.dedent("""
                #include <string>
                #define TWICE(x) ((x) * 2)
                struct S { int get() const { return 1; } bool m(int a); };
                template <class T> T id(T v) { return v; }
                static const int k = TWICE(3);
                extern "C" { bool c_fn(const int* a) { return a != nullptr; } }
                const char* s = "bool fake(int x);";
                bool g(void);
                bool h(const std::string * const s, std::vector<int> & v) noexcept;
                """))
        fns = fm.parse_header(path)
        self.assertEqual([f.name for f in fns], ["c_fn", "g", "h"])
        self.assertEqual(fns[2].inputs, [("s", "std::string")])
        self.assertEqual(fns[2].outputs, [("v", "std::vector<int>")])

    def test_compile_error_names_header_line(self):
        self.fails("bool f(const int* a, int& b) {\n  b = *a +;\n  return true;\n}\n",
                   r"(?s)nodes.h: compiling the FN factory module failed.*nodes.h:2:")

    def test_missing_header(self):
        with self.assertRaisesRegex(fm.FactoryModuleError, r"File \[nope.h\] can't be found"):
            fm.build("nope.h", self.tmp.name)
        with contextlib.redirect_stderr(io.StringIO()) as err:
            self.assertEqual(fm.main(["nope.h"]), 1)
        self.assertIn("build_fn_factory_module.sh: error: File [nope.h]", err.getvalue())


if __name__ == "__main__":
    unittest.main()
