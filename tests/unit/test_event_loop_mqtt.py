"""Unit tests of the graph's MQTT 3.1.1 client (python/nrp_core/event_loop/_mqtt.py).

Packets: the remaining-length encoding at its boundaries, UTF-8 strings, broker addresses.
FakeBroker (a socket the test scripts): the exact CONNECT, SUBSCRIBE, PUBLISH (QoS 0 and 1),
PUBACK and DISCONNECT bytes the client sends, what it does with the broker's answers (a refused
CONNACK, a server that is no broker, incoming QoS 1 messages split across reads), PINGREQ when
idle. Mosquitto (Debian's /usr/sbin/mosquitto, skipped without it): payloads of 0 B to 300 kB
round trip between two clients; LocalBroker starts one on a free port and stops it.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_event_loop_mqtt
"""
import os
import socket
import tempfile
import threading
import time
import unittest

from nrp_core.event_loop import _mqtt
from nrp_core.event_loop._mqtt import (LocalBroker, MqttConnection, MqttError, is_local,
                                       parse_broker)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def read_packet(sock):
    """(first byte, body) of one packet from `sock`."""
    def exact(n):
        out = b""
        while len(out) < n:
            chunk = sock.recv(n - len(out))
            if not chunk:
                raise EOFError
            out += chunk
        return out
    first = exact(1)[0]
    length, shift = 0, 0
    while True:
        b = exact(1)[0]
        length |= (b & 0x7F) << shift
        shift += 7
        if not b & 0x80:
            break
    return first, exact(length)


class FakeBroker:
    """Accepts one connection; `script(conn)` runs on it in a thread."""

    def __init__(self, script):
        self.server = socket.socket()
        self.server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(1)
        self.address = "127.0.0.1:%d" % self.server.getsockname()[1]
        self.error = None
        self.packets = []
        self.thread = threading.Thread(target=self._run, args=(script,), daemon=True)
        self.thread.start()

    def _run(self, script):
        try:
            conn, _ = self.server.accept()
            conn.settimeout(5)
            with conn:
                script(self, conn)
        except Exception as e:  # noqa: BLE001 - reported by join()
            self.error = e

    def read(self, conn):
        packet = read_packet(conn)
        self.packets.append(packet)
        return packet

    def join(self):
        self.thread.join(10)
        self.server.close()
        if self.error is not None:
            raise self.error


CONNACK_OK = b"\x20\x02\x00\x00"


class Packets(unittest.TestCase):
    def test_remaining_length_boundaries(self):
        # MQTT 3.1.1, 2.2.3: 1 to 4 bytes, 7 bits each, low first.
        for n, encoded in [(0, b"\x00"), (127, b"\x7f"), (128, b"\x80\x01"),
                           (16383, b"\xff\x7f"), (16384, b"\x80\x80\x01"),
                           (2097151, b"\xff\xff\x7f"), (2097152, b"\x80\x80\x80\x01")]:
            packet = _mqtt._packet(0x30, b"x" * n)
            self.assertEqual(packet[:1 + len(encoded)], b"\x30" + encoded, n)
            self.assertEqual(len(packet), 1 + len(encoded) + n)

    def test_utf8_strings(self):
        self.assertEqual(_mqtt._utf8("MQTT"), b"\x00\x04MQTT")
        self.assertEqual(_mqtt._utf8(""), b"\x00\x00")
        self.assertEqual(_mqtt._utf8("é/ü"), b"\x00\x05" + "é/ü".encode())

    def test_broker_addresses(self):
        self.assertEqual(parse_broker("localhost"), ("localhost", 1883))
        self.assertEqual(parse_broker("host:1884"), ("host", 1884))
        self.assertEqual(parse_broker(" tcp://10.0.0.1:8883 "), ("10.0.0.1", 8883))
        self.assertEqual(parse_broker("mqtt://b"), ("b", 1883))
        self.assertEqual(parse_broker("[::1]:1885"), ("::1", 1885))
        for bad, needle in [("ws://h:1", "scheme"), ("h:port", "number"), ("h:0", "host:port"),
                            (":1883", "host:port"), ("h:70000", "host:port")]:
            with self.assertRaisesRegex(ValueError, needle):
                parse_broker(bad)
        self.assertTrue(is_local("localhost") and is_local("127.0.0.5") and is_local("::1"))
        self.assertFalse(is_local("10.0.0.1") or is_local("mqtt.example.org"))


class AgainstFakeBroker(unittest.TestCase):
    def test_connect_subscribe_publish_disconnect(self):
        got = []

        def script(b, conn):
            first, body = b.read(conn)
            conn.sendall(CONNACK_OK)
            first, body = b.read(conn)                     # SUBSCRIBE
            conn.sendall(b"\x90\x03" + body[:2] + b"\x01")  # SUBACK, QoS 1 granted
            b.read(conn)                                   # PUBLISH QoS 1
            b.read(conn)                                   # PUBLISH QoS 0
            # A QoS 1 message for the client, sent in three pieces.
            msg = _mqtt._packet(0x32, _mqtt._utf8("a/b") + b"\x12\x34" + b"\x00\xffdata")
            for part in (msg[:1], msg[1:6], msg[6:]):
                conn.sendall(part)
                time.sleep(0.02)
            b.read(conn)                                   # its PUBACK
            b.read(conn)                                   # DISCONNECT

        broker = FakeBroker(script)
        client = MqttConnection(broker.address, "cid-1", keepalive=30)
        client.subscribe("a/b", got.append)
        client.publish("t", b"\x00\x01", qos=1)
        client.publish("t", "text", qos=0)
        deadline = time.monotonic() + 5
        while not got and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(0.05)
        client.close()
        broker.join()
        self.assertEqual(got, [b"\x00\xffdata"])
        (c_first, connect), (s_first, sub), (p1_first, pub1), (p0_first, pub0), \
            (a_first, ack), (d_first, disc) = broker.packets
        # CONNECT: protocol "MQTT" level 4, clean session, keepalive 30, the client id.
        self.assertEqual(c_first, 0x10)
        self.assertEqual(connect, b"\x00\x04MQTT\x04\x02\x00\x1e\x00\x05cid-1")
        # SUBSCRIBE (flags 0010), a packet id, the filter, QoS 1.
        self.assertEqual(s_first, 0x82)
        self.assertEqual(sub[2:], b"\x00\x03a/b\x01")
        self.assertNotEqual(sub[:2], b"\x00\x00")
        # PUBLISH QoS 1: the topic, a packet id other than the SUBSCRIBE's, the payload.
        self.assertEqual(p1_first, 0x32)
        self.assertEqual(pub1[:3], b"\x00\x01t")
        self.assertNotIn(pub1[3:5], (b"\x00\x00", sub[:2]))
        self.assertEqual(pub1[5:], b"\x00\x01")
        # PUBLISH QoS 0: no packet id; a str goes as UTF-8.
        self.assertEqual((p0_first, pub0), (0x30, b"\x00\x01ttext"))
        self.assertEqual((a_first, ack), (0x40, b"\x12\x34"))  # PUBACK with the message's id
        self.assertEqual((d_first, disc), (0xE0, b""))
        self.assertFalse(client.connected)

    def test_refused_connection(self):
        def script(b, conn):
            b.read(conn)
            conn.sendall(b"\x20\x02\x00\x05")  # not authorized
        broker = FakeBroker(script)
        with self.assertRaisesRegex(MqttError, "refused the connection.*code 5"):
            MqttConnection(broker.address, "c")
        broker.join()

    def test_not_a_broker(self):
        def script(b, conn):
            conn.recv(100)
            conn.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n")
        broker = FakeBroker(script)
        with self.assertRaisesRegex(MqttError, "did not answer as an MQTT broker"):
            MqttConnection(broker.address, "c")
        broker.join()

    def test_nothing_listens(self):
        port = free_port()
        with self.assertRaisesRegex(MqttError, "cannot connect to the MQTT broker 127.0.0.1:%d"
                                    % port):
            MqttConnection("127.0.0.1:%d" % port, "c", timeout=1)

    def test_ping_when_idle(self):
        def script(b, conn):
            b.read(conn)
            conn.sendall(CONNACK_OK)
            first, _ = b.read(conn)  # within the keepalive, with nothing else to send
            if first == 0xC0:
                conn.sendall(b"\xd0\x00")  # PINGRESP
            b.read(conn)
        broker = FakeBroker(script)
        client = MqttConnection(broker.address, "c", keepalive=2)
        time.sleep(1.6)
        client.close()
        broker.join()
        self.assertEqual([p[0] for p in broker.packets], [0x10, 0xC0, 0xE0])

    def test_a_failing_callback_keeps_the_connection(self):
        got = []

        def script(b, conn):
            b.read(conn)
            conn.sendall(CONNACK_OK)
            b.read(conn)
            for payload in (b"boom", b"ok"):
                conn.sendall(_mqtt._packet(0x30, _mqtt._utf8("t") + payload))
            b.read(conn)

        def callback(payload):
            if payload == b"boom":
                raise RuntimeError("a subscriber's bug")
            got.append(payload)
        broker = FakeBroker(script)
        client = MqttConnection(broker.address, "c")
        client.subscribe("t", callback)
        deadline = time.monotonic() + 5
        while not got and time.monotonic() < deadline:
            time.sleep(0.01)
        client.close()
        broker.join()
        self.assertEqual(got, [b"ok"])


@unittest.skipUnless(os.access(_mqtt.MOSQUITTO, os.X_OK), "no mosquitto (Debian package)")
class AgainstMosquitto(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.address = "127.0.0.1:%d" % free_port()
        cls.broker = LocalBroker.ensure(cls.address, os.path.join(cls.tmp.name, "mosq.log"))

    @classmethod
    def tearDownClass(cls):
        cls.broker.stop()
        cls.tmp.cleanup()

    def test_payloads_round_trip(self):
        got, done = [], threading.Event()
        sizes = [0, 1, 127, 128, 16383, 16384, 300_000]

        def on(payload):
            got.append(payload)
            if len(got) == len(sizes):
                done.set()
        a = MqttConnection(self.address, "convoy-test-a")
        b = MqttConnection(self.address, "convoy-test-b")
        try:
            b.subscribe("convoy/test/bin", on)
            time.sleep(0.2)  # the SUBACK
            sent = [bytes((i * 7 + n) % 256 for i in range(n)) for n in sizes]
            for payload in sent:
                a.publish("convoy/test/bin", payload)
            self.assertTrue(done.wait(10), [len(g) for g in got])
        finally:
            a.close()
            b.close()
        self.assertEqual(got, sent)  # QoS 1, one connection: in order, none lost

    def test_ensure_uses_a_running_broker(self):
        self.assertIsNone(LocalBroker.ensure(self.address, os.path.join(self.tmp.name, "x.log")))

    def test_a_started_broker_stops(self):
        address = "localhost:%d" % free_port()
        broker = LocalBroker.ensure(address, os.path.join(self.tmp.name, "y.log"))
        self.assertIsNotNone(broker)
        MqttConnection(address, "c").close()
        broker.stop()
        self.assertIsNotNone(broker.proc.poll())
        with self.assertRaises(MqttError):
            MqttConnection(address, "c", timeout=1)

    def test_remote_broker_is_not_started(self):
        with self.assertRaisesRegex(MqttError, "no MQTT broker answers at 192.0.2.1:1883"):
            LocalBroker.ensure("192.0.2.1:1883", os.path.join(self.tmp.name, "z.log"))


if __name__ == "__main__":
    unittest.main()
