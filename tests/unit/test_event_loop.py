"""Unit tests of nrp_core.event_loop, Convoy's NRP-Core computational graph (no coordinator:
engines, MQTT and ROS are fakes)."""
import inspect
import logging
import os
import tempfile
import textwrap
import unittest

from nrp_core._datapacks import JsonDataPack
from nrp_core.event_loop import (ComputationalGraphError, EngineLink, EventLoop, ExecutionMode,
                                 FTIStep, MQTTClient, ROSInterface, Transports,
                                 load_computational_graph, node_policies)
import nrp_core.event_loop as el

logging.getLogger("nrp_core.event_loop").setLevel(logging.ERROR)

HEADER = "from nrp_core.event_loop import *\nfrom nrp_core.data.nrp_json import JsonDataPack\n"


class FakeBroker(MQTTClient):
    """Delivers each publish at once to the topic's subscribers (seen at the next cycle)."""

    def __init__(self):
        self.subs, self.published = {}, []

    def subscribe(self, topic, callback):
        self.subs.setdefault(topic, []).append(callback)

    def publish(self, topic, payload):
        self.published.append((topic, payload))
        for cb in self.subs.get(topic, []):
            cb(payload)


class FakeRos(ROSInterface):
    def __init__(self):
        self.subs, self.published, self.spins = {}, [], 0

    def subscribe(self, topic, msg_type, callback):
        self.subs[topic] = callback

    def publish(self, topic, msg_type, msg):
        self.published.append((topic, msg))

    def spin_once(self):
        self.spins += 1


class Twist:  # looks like a rospy message class
    _type, _md5sum = "geometry_msgs/Twist", "9f195f881246fdfa2798d1d3eebca84a"

    def __init__(self, x=0.0):
        self.x = x


class FakeEngines:
    """DataPackSource and DataPackSink of the loop."""

    def __init__(self):
        self.datapacks, self.sent = {}, []

    def get_datapacks(self, engine, names):
        return [self.datapacks[(engine, n)] for n in names if (engine, n) in self.datapacks]

    def send_datapacks(self, engine, datapacks):
        self.sent.append((engine, datapacks))


def _proto_class(package, name, fields):
    """A protobuf message class built at run time (number, name, type) in a private pool."""
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    pool = descriptor_pool.DescriptorPool()
    f = descriptor_pb2.FileDescriptorProto(name=package + ".proto", package=package,
                                           syntax="proto3")
    m = f.message_type.add(name=name)
    for number, field, ftype in fields:
        m.field.add(name=field, number=number, type=ftype, label=1)
    pool.Add(f)
    d = pool.FindMessageTypeByName(package + "." + name)
    get = getattr(message_factory, "GetMessageClass", None)
    return get(d) if get else message_factory.MessageFactory(pool).GetPrototype(d)


class GraphTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)

    def load(self, source, exec_mode="AllNodes", transports=None, name="cg.py", **kw):
        path = os.path.join(self.dir.name, name)
        with open(path, "w") as f:
            f.write(HEADER + textwrap.dedent(source))
        return load_computational_graph([name], exec_mode, transports, self.dir.name, **kw)

    def g(self, graph):
        """The globals the loaded file shares (to read what its functions recorded)."""
        return next(iter(graph.nodes_of("FunctionalNode"))).function.__globals__


class ApiTest(unittest.TestCase):
    def test_policy_spellings(self):
        p = node_policies
        self.assertIs(p.input_node.msg_cache.keep, p.input_node.keep)
        for v in (p.input_node.msg_cache.clear, p.input_node.msg_publish.last,
                  p.input_node.msg_publish.all, p.functional_node.exec_policy.on_new_message,
                  p.functional_node.exec_policy.always, p.output_node.publish_format.series):
            self.assertTrue(repr(v).startswith("nrp_core.event_loop.node_policies."))

    def test_signatures_and_defaults(self):
        def params(cls):
            return {k: v.default for k, v in
                    list(inspect.signature(cls.__init__).parameters.items())[1:]}
        e = inspect.Parameter.empty
        p = node_policies
        self.assertEqual(params(el.FunctionalNode), {
            "name": e, "outputs": e, "exec_policy": p.functional_node.exec_policy.on_new_message})
        self.assertEqual(params(el.FromEngine), {"keyword": e, "address": e,
                                                 "cache_policy": p.input_node.msg_cache.keep})
        self.assertEqual(params(el.ToEngine), {"keyword": e, "address": e})
        self.assertEqual(params(el.FromFunctionalNode), {"keyword": e, "address": e})
        for sub in (el.MQTTSubscriber, el.RosSubscriber):
            self.assertEqual(params(sub), {"keyword": e, "address": e, "type": e,
                                           "publish_policy": p.input_node.msg_publish.last,
                                           "cache_policy": p.input_node.msg_cache.keep})
        for pub in (el.MQTTPublisher, el.RosPublisher):
            self.assertEqual(params(pub), {"keyword": e, "address": e, "type": e,
                                           "publish_from_cache": False, "compute_period": 1})
        self.assertEqual(params(el.Clock), {"keyword": e})
        self.assertEqual(params(el.Iteration), {"keyword": e})

    def test_wrong_policy_type(self):
        with self.assertRaisesRegex(TypeError, "cache_policy"):
            el.FromEngine("a", "/e/d", node_policies.input_node.msg_publish.all)

    def test_factory_module_missing(self):  # C++ nodes: test_event_loop_cpp.py
        with self.assertRaisesRegex(ComputationalGraphError, "could not be loaded: not found"):
            el.createFNFromFactoryModule("libFNFactoryModule.so", "f", "n",
                                         node_policies.functional_node.exec_policy.always)


class OrderTest(GraphTest):
    def test_layers_and_order(self):
        graph = self.load("""
            ran = []
            @FromFunctionalNode('x', '/b/o')
            @OutputDummy('o', 'out')
            @FunctionalNode(name='c', outputs=['o'], exec_policy=node_policies.functional_node.exec_policy.always)
            def c(x):
                ran.append('c'); return [x]
            @FromFunctionalNode('x', '/a/o')
            @FunctionalNode(name='b', outputs=['o'], exec_policy=node_policies.functional_node.exec_policy.always)
            def b(x):
                ran.append('b'); return [x + 1]
            @InputDummy('x', 'in', 1)
            @FunctionalNode(name='a', outputs=['o'])
            def a(x):
                ran.append('a'); return [x * 10]
            @FromFunctionalNode('y', '/a/o')
            @FromFunctionalNode('z', '/b/o')
            @FunctionalNode(name='d', outputs=[])
            def d(y, z):
                ran.append('d')
            @FunctionalNode(name='lonely', outputs=[])
            def lonely():
                ran.append('lonely')
        """)
        self.assertEqual(graph.layers(), [["in"], ["a"], ["b"], ["c", "d"], ["out"]])
        graph.compute()
        self.assertEqual(self.g(graph)["ran"], ["a", "b", "c", "d"])  # lonely never runs
        self.assertEqual(graph.nodes["out"].sent, [11])

    def test_cycle_named(self):
        with self.assertRaises(ComputationalGraphError) as cm:
            self.load("""
                @InputDummy('i', 'in', 1)
                @FromFunctionalNode('x', '/q/o')
                @FunctionalNode(name='p', outputs=['o'])
                def p(i, x): return [x]
                @FromFunctionalNode('x', '/p/o')
                @FunctionalNode(name='q', outputs=['o'])
                def q(x): return [x]
                @FromFunctionalNode('x', '/q/o')
                @FunctionalNode(name='after', outputs=[])
                def after(x): pass
            """)
        msg = str(cm.exception)
        self.assertIn("Cycle(s) found in the graph", msg)
        self.assertRegex(msg, r'"(p|q)" -> "(p|q)" -> "(p|q)"')
        self.assertIn('"after"', msg)

    def test_unknown_f2f_node_and_output(self):
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r"(?s)'/nowhere/o'.*input \"x\" of node \"f\".*'nowhere'"):
            self.load("""
                @FromFunctionalNode('x', '/nowhere/o')
                @FunctionalNode(name='f', outputs=[])
                def f(x): pass
            """)
        with self.assertRaisesRegex(ComputationalGraphError, "doesn't have a declared output 'p'"):
            self.load("""
                @FunctionalNode(name='g', outputs=['o'])
                def g(): return [1]
                @FromFunctionalNode('x', '/g/p')
                @FunctionalNode(name='f', outputs=[])
                def f(x): pass
            """)

    def test_unknown_keyword(self):
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r'"input_wrong" does not match any of the declared input '
                                    r'arguments in node "function4"'):
            self.load("""
                @InputDummy('input_wrong', 'idummy1', 10)
                @FunctionalNode(name='function4', outputs=["output1"])
                def wrong_i_port(input1):
                    return [input1]
            """)
        with self.assertRaisesRegex(ComputationalGraphError, '"nope" does not match any of the '
                                    'declared outputs of node "f"'):
            self.load("""
                @OutputDummy('nope', 'o')
                @FunctionalNode(name='f', outputs=['out'])
                def f(): return [1]
            """)

    def test_decorator_order_and_duplicates(self):
        with self.assertRaisesRegex(ComputationalGraphError, "must be a FunctionalNode"):
            self.load("""
                @FunctionalNode(name='f', outputs=[])
                @InputDummy('x', 'in', 1)
                def f(x): pass
            """)
        with self.assertRaisesRegex(ComputationalGraphError, 'Duplicated Node Name.*"f"'):
            self.load("""
                @FunctionalNode(name='f', outputs=[])
                def f(): pass
                @FunctionalNode(name='f', outputs=[])
                def g(): pass
            """)
        with self.assertRaisesRegex(ComputationalGraphError, "can only have 1 subscriber"):
            self.load("""
                @InputDummy('x', 'in', 1)
                @InputDummy('x', 'in2', 2)
                @FunctionalNode(name='f', outputs=[])
                def f(x): pass
            """)
        with self.assertRaisesRegex(ComputationalGraphError, "publish from cache"):
            self.load("""
                @InputDummy('input1', 'idummy1', 10)
                @OutputDummy('output1', 'odummy2', publish_from_cache=True)
                @FunctionalNode(name='function2', outputs=["output1"])
                def f_node_connected(input1): return [input1]
                @InputDummy('input1', 'idummy1', 10)
                @OutputDummy('output1', 'odummy2', publish_from_cache=True)
                @FunctionalNode(name='function3', outputs=["output1"])
                def f_node_f2f(input1): return [input1]
            """)

    def test_bad_return(self):
        graph = self.load("""
            @InputDummy('x', 'in', 1)
            @FunctionalNode(name='f', outputs=['a', 'b'])
            def f(x): return [1]
        """)
        with self.assertRaisesRegex(ComputationalGraphError, '"f" has 2 declared outputs, but '
                                    'returns 1 elements'):
            graph.compute()
        graph = self.load("""
            @InputDummy('x', 'in', 1)
            @FunctionalNode(name='f', outputs=[])
            def f(x): raise KeyError('boom')
        """)
        with self.assertRaisesRegex(ComputationalGraphError, '(?s)id "f".*KeyError'):
            graph.compute()


class PolicyTest(GraphTest):
    SRC = """
        seen = []
        @FromEngine('dp', '/eng/dp1', cache_policy=node_policies.input_node.msg_cache.{cache})
        @ToEngine('out', '/eng')
        @FunctionalNode(name='f', outputs=['out'], exec_policy=node_policies.functional_node.exec_policy.{ex})
        def f(dp):
            seen.append(None if dp is None else dp.data['v'])
            if dp is not None:
                out = JsonDataPack('cmd', 'eng'); out.data['v'] = dp.data['v'] * 2
                return [out]
    """

    def run_cycles(self, cache, ex, feed):
        graph = self.load(self.SRC.format(cache=cache, ex=ex))
        link, engines = EngineLink(graph), FakeEngines()
        self.assertEqual(link.requested("eng"), ["dp1"])
        for v in feed:
            engines.datapacks.clear()
            if v is not None:
                engines.datapacks[("eng", "dp1")] = JsonDataPack("dp1", "eng", {"v": v})
            link.update_from_engines(engines, ["eng"])
            graph.compute()
            link.send_to_engines(engines, ["eng"])
        return self.g(graph)["seen"], engines.sent

    def test_on_new_message_keep(self):
        seen, sent = self.run_cycles("keep", "on_new_message", [1, None, 2])
        self.assertEqual(seen, [1, 2])
        self.assertEqual([[d.data["v"] for d in dps] for _, dps in sent], [[2], [4]])

    def test_always_keep_and_clear(self):
        self.assertEqual(self.run_cycles("keep", "always", [1, None, 2])[0], [1, 1, 2])
        self.assertEqual(self.run_cycles("clear", "always", [1, None, 2])[0], [1, None, 2])
        # clear publishes None, which is no new input
        self.assertEqual(self.run_cycles("clear", "on_new_message", [1, None, 2])[0], [1, 2])

    def test_empty_datapack_does_not_replace(self):
        graph = self.load(self.SRC.format(cache="keep", ex="always"))
        node = graph.nodes["eng_input"]
        node.set_datapacks([JsonDataPack("dp1", "eng", {"v": 5})])
        graph.compute()
        from nrp_core._datapacks import EmptyDataPack
        node.set_datapacks([EmptyDataPack("dp1", "eng"), JsonDataPack("other", "eng")])
        graph.compute()
        self.assertEqual(self.g(graph)["seen"], [5, 5])

    def test_publish_all_and_last(self):
        broker = FakeBroker()
        graph = self.load("""
            got = []
            @MQTTSubscriber('m', 'topic_a', str, publish_policy=node_policies.input_node.msg_publish.all)
            @MQTTSubscriber('n', 'topic_b', str)
            @FunctionalNode(name='f', outputs=[])
            def f(m, n): got.append((m, n))
        """, transports=Transports(mqtt=broker))
        for p in (b"1", b"2", b"3"):
            broker.publish("topic_a", p)
            broker.publish("topic_b", p)
        graph.compute()
        graph.compute()  # nothing new: not run
        self.assertEqual(self.g(graph)["got"], [(["1", "2", "3"], "3")])

    def test_publish_from_cache_and_period(self):
        graph = self.load("""
            n = [0]
            @Iteration('it')
            @OutputDummy('a', 'cached', publish_from_cache=True)
            @OutputDummy('b', 'every2', compute_period=2)
            @OutputDummy('c', 'plain')
            @FunctionalNode(name='f', outputs=['a', 'b', 'c'])
            def f(it):
                return [it, it, it] if it == 0 else None
        """)
        for i in range(4):
            graph.nodes["iteration_node"].update(i)
            graph.compute()
        self.assertEqual(graph.nodes["cached"].sent, [0, 0, 0, 0])
        self.assertEqual(graph.nodes["every2"].sent, [0])
        self.assertEqual(graph.nodes["plain"].sent, [0])


class ModeTest(GraphTest):
    SRC = """
        ran = []
        @Iteration('it')
        @FunctionalNode(name='src', outputs=['o'], exec_policy=node_policies.functional_node.exec_policy.always)
        def src(it):
            ran.append('src'); return [it]
        @FromFunctionalNode('x', '/src/o')
        @OutputDummy('o', 'out', compute_period=2)
        @FunctionalNode(name='to_out', outputs=['o'], exec_policy=node_policies.functional_node.exec_policy.always)
        def to_out(x):
            ran.append('to_out'); return [x]
        @FromFunctionalNode('x', '/src/o')
        @FunctionalNode(name='sink', outputs=[], exec_policy=node_policies.functional_node.exec_policy.always)
        def sink(x):
            ran.append('sink')
    """

    def run_mode(self, mode):
        graph = self.load(self.SRC, exec_mode=mode)
        for i in range(4):
            graph.nodes["iteration_node"].update(i)
            graph.compute()
        return self.g(graph)["ran"], graph.nodes["out"].sent

    def test_all_nodes(self):
        ran, sent = self.run_mode(ExecutionMode.ALL_NODES)
        self.assertEqual(ran, ["src", "to_out", "sink"] * 4)
        self.assertEqual(sent, [0, 2])

    def test_output_driven(self):
        ran, sent = self.run_mode(ExecutionMode.OUTPUT_DRIVEN)
        self.assertEqual(ran, ["src", "to_out"] * 2)  # cycles 0 and 2; the sink never runs
        self.assertEqual(sent, [0, 2])

    def test_bad_mode(self):
        with self.assertRaisesRegex(ValueError, "OutputDriven"):
            self.load(self.SRC, exec_mode="Sometimes")


class LoaderTest(GraphTest):
    def test_missing_file(self):
        with self.assertRaisesRegex(ComputationalGraphError, r'Loading of computation graph file '
                                    r'"nope.py" failed: the file doesn\'t exist.'):
            load_computational_graph(["nope.py"], base_dir=self.dir.name)

    def test_python_error(self):
        with self.assertRaisesRegex(ComputationalGraphError,
                                    r'(?s)file "cg.py" failed: .*NameError.*undefined_name'):
            self.load("x = undefined_name\n")
        with self.assertRaisesRegex(ComputationalGraphError, r"(?s)failed: .*SyntaxError"):
            self.load("def (:\n")
        with self.assertRaisesRegex(ComputationalGraphError, "(?s)failed: .*MQTT node type must "
                                    "be either"):
            self.load("""
                @MQTTSubscriber('m', 't', int)
                @FunctionalNode(name='f', outputs=[])
                def f(m): pass
            """)

    def test_shared_globals_and_forward_edges(self):
        with open(os.path.join(self.dir.name, "a.py"), "w") as f:
            f.write(HEADER + textwrap.dedent("""
                FACTOR = 3
                @FromFunctionalNode('x', '/b/o')
                @OutputDummy('y', 'out')
                @FunctionalNode(name='a', outputs=['y'])
                def a(x): return [x * FACTOR]
            """))
        with open(os.path.join(self.dir.name, "b.py"), "w") as f:
            f.write(HEADER + textwrap.dedent("""
                @InputDummy('x', 'in', FACTOR)
                @FunctionalNode(name='b', outputs=['o'])
                def b(x): return [x + 1]
            """))
        graph = load_computational_graph(["a.py", "b.py"], base_dir=self.dir.name)
        graph.compute()
        self.assertEqual(graph.nodes["out"].sent, [12])

    def test_reserved_time_node_name(self):
        with self.assertRaisesRegex(ComputationalGraphError, "reserved for the input Clock node"):
            self.load("""
                @InputDummy('x', 'clock_node', 1)
                @FunctionalNode(name='f', outputs=[])
                def f(x): pass
            """)


class LoopTest(GraphTest):
    def test_event_loop_timestep_timeout_clock(self):
        graph = self.load("""
            ticks = []
            @Clock('c')
            @Iteration('i')
            @FunctionalNode(name='f', outputs=[])
            def f(c, i): ticks.append((c, i))
        """)
        now = [0.0]
        ros = FakeRos()
        loop = EventLoop(graph, timestep=0.1, ros=ros, clock=lambda: now[0],
                         sleep=lambda s: now.__setitem__(0, round(now[0] + s, 6)))
        loop.run(timeout=1.0)
        ticks = self.g(graph)["ticks"]
        self.assertEqual(len(ticks), 10)
        self.assertEqual([i for _, i in ticks], list(range(10)))
        self.assertEqual([c for c, _ in ticks][:3], [0, 100, 200])
        self.assertEqual(ros.spins, 10)

    def test_fti_step(self):
        graph = self.load("""
            @FromEngine('a', '/eng_a/state')
            @Clock('t')
            @ToEngine('cmd', '/eng_b')
            @FunctionalNode(name='ctl', outputs=['cmd'])
            def ctl(a, t):
                out = JsonDataPack('cmd', 'eng_b'); out.data['v'] = a.data['v']; out.data['t'] = t
                return [out]
        """, fti_loop=True)
        self.assertEqual(graph.exec_mode, ExecutionMode.OUTPUT_DRIVEN)
        engines, step = FakeEngines(), FTIStep(graph, EngineLink(graph))
        engines.datapacks[("eng_a", "state")] = JsonDataPack("state", "eng_a", {"v": 7})
        step.step(engines, engines, ["eng_a"], 20, 0)  # eng_b not synced: nothing computed
        self.assertEqual(engines.sent, [])
        engines.datapacks[("eng_a", "state")] = JsonDataPack("state", "eng_a", {"v": 8})
        step.step(engines, engines, ["eng_a", "eng_b"], 40, 1)
        self.assertEqual(len(engines.sent), 1)
        engine, dps = engines.sent[0]
        self.assertEqual((engine, dps[0].data), ("eng_b", {"v": 8, "t": 40}))


class TransportTest(GraphTest):
    def test_ros_nodes(self):
        ros = FakeRos()
        graph = self.load("""
            import sys
            Twist = sys.modules['test_event_loop'].Twist
            @RosSubscriber('cmd', '/in', Twist)
            @RosPublisher('out', '/out', Twist)
            @FunctionalNode(name='f', outputs=['out'])
            def f(cmd): return [Twist(cmd.x * 2)]
        """, transports=Transports(ros=ros))
        ros.subs["/in"](Twist(1.5))
        graph.compute()
        self.assertEqual([(t, m.x) for t, m in ros.published], [("/out", 3.0)])

    def test_ros_errors(self):
        with self.assertRaisesRegex(ComputationalGraphError, "nrp_core.data.nrp_ros"):
            el.RosSubscriber("a", "/t", int)
        with self.assertRaisesRegex(ComputationalGraphError, "ROSNode"):
            self.load("""
                import sys
                Twist = sys.modules['test_event_loop'].Twist
                @RosSubscriber('cmd', '/in', Twist)
                @FunctionalNode(name='f', outputs=[])
                def f(cmd): pass
            """)

    def test_mqtt_without_client_warns(self):
        graph = self.load("""
            @MQTTSubscriber('m', 't', str)
            @MQTTPublisher('o', 't', str)
            @FunctionalNode(name='f', outputs=['o'], exec_policy=node_policies.functional_node.exec_policy.always)
            def f(m): return ['x']
        """)
        graph.compute()  # no MQTT: nothing sent, no error

    def test_bad_mqtt_payload(self):
        broker = FakeBroker()
        graph = self.load("""
            @MQTTSubscriber('m', 'dp', JsonDataPack)
            @FunctionalNode(name='f', outputs=[])
            def f(m): pass
        """, transports=Transports(mqtt=broker))
        broker.publish("dp", b'{"name": "x"}')
        with self.assertRaisesRegex(ComputationalGraphError, '(?s)dp_input.*name and engine_name'):
            graph.compute()


if __name__ == "__main__":
    unittest.main()
