"""A small MQTT 3.1.1 client (QoS 0 and 1, clean session) and the local broker the coordinator
starts when none answers: the graph's MQTTClient (NRP-Core's NRPMQTTProxy) and the transport of
the asynchronous engines (_mqtt_engine.py). Pure Python: no paho.

  client = MqttConnection("localhost:1883", "NRP-core-client")   # connects, or MqttError
  client.subscribe("topic", callback)    # callback(payload: bytes) on the reader thread
  client.publish("topic", b"payload")    # QoS 1, not retained
  client.close()

  broker = LocalBroker.ensure("localhost:1883", log_file)   # None if one answers already
  broker.stop()
"""
import ctypes
import logging
import os
import pwd
import socket
import struct
import subprocess
import threading
import time

from ._transport import MQTTClient

_log = logging.getLogger("nrp_core.event_loop")

MOSQUITTO = "/usr/sbin/mosquitto"
DEFAULT_BROKER = "localhost:1883"
_LOCAL_HOSTS = ("localhost", "127.0.0.1", "::1", "ip6-localhost", "0.0.0.0", "")


class MqttError(RuntimeError):
    """The broker cannot be reached or refused the connection."""


def parse_broker(address):
    """(host, port) of "host", "host:port", "tcp://host:port" or "mqtt://host:port"."""
    text = address.strip()
    for scheme in ("tcp://", "mqtt://"):
        if text.startswith(scheme):
            text = text[len(scheme):]
            break
    else:
        if "://" in text:
            raise ValueError('"%s": the scheme must be tcp:// or mqtt://' % address)
    host, sep, port = text.rpartition(":")
    if not sep or "]" in port:
        host, port = text, "1883"
    host = host.strip("[]")
    try:
        port_number = int(port)
    except ValueError:
        raise ValueError('"%s": the port must be a number' % address) from None
    if not host or not 0 < port_number < 65536:
        raise ValueError('"%s" is not host:port' % address)
    return host, port_number


def is_local(host):
    return host in _LOCAL_HOSTS or host.startswith("127.")


def _utf8(text):
    data = text.encode("utf-8")
    return struct.pack("!H", len(data)) + data


def _packet(kind, body):
    n, length = len(body), b""
    while True:
        byte, n = n % 128, n // 128
        length += bytes([byte | (0x80 if n else 0)])
        if not n:
            return bytes([kind]) + length + body


class MqttConnection(MQTTClient):
    """One connection to a broker; a reader thread calls the subscribers' callbacks."""

    def __init__(self, broker, client_id, keepalive=30, timeout=3.0):
        self.broker = broker
        host, port = parse_broker(broker)
        self._lock = threading.Lock()
        self._callbacks = {}
        self._next_id = 0
        self._keepalive = keepalive
        self._closed = False
        try:
            self._sock = socket.create_connection((host, port), timeout=timeout)
        except OSError as e:
            raise MqttError("cannot connect to the MQTT broker %s: %s"
                            % (broker, e.strerror or e)) from None
        self._sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        body = _utf8("MQTT") + bytes([4, 0x02]) + struct.pack("!H", keepalive) + _utf8(client_id)
        try:
            self._sock.sendall(_packet(0x10, body))
            # The first byte alone: a server that is no broker may answer little, then close.
            kind = self._read_exact(1)[0]
            payload = self._read_rest() if kind == 0x20 else b""
        except (OSError, EOFError) as e:
            self._sock.close()
            raise MqttError("the MQTT broker %s did not answer: %s" % (broker, e)) from None
        if kind >> 4 != 2 or len(payload) < 2:
            self._sock.close()
            raise MqttError("%s did not answer as an MQTT broker" % broker)
        if payload[1] != 0:
            self._sock.close()
            raise MqttError("the MQTT broker %s refused the connection (CONNACK return code %d)"
                            % (broker, payload[1]))
        self._sock.settimeout(max(1.0, keepalive / 2.0))
        self._last_sent = time.monotonic()
        self._reader = threading.Thread(target=self._read_loop, name="mqtt-reader", daemon=True)
        self._reader.start()

    # --- MQTTClient --------------------------------------------------------------------
    def subscribe(self, topic, callback):
        with self._lock:
            self._callbacks.setdefault(topic, []).append(callback)
        self._send(0x82, struct.pack("!H", self._packet_id()) + _utf8(topic) + b"\x01")

    def publish(self, topic, payload, qos=1, retain=False):
        if isinstance(payload, str):
            payload = payload.encode("utf-8")
        header = _utf8(topic) + (struct.pack("!H", self._packet_id()) if qos else b"")
        self._send(0x30 | (qos << 1) | (1 if retain else 0), header + bytes(payload))

    def close(self):
        if self._closed:
            return
        self._closed = True
        try:
            self._send(0xE0, b"")
            self._sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass
        self._reader.join(timeout=2)
        self._sock.close()

    @property
    def connected(self):
        return not self._closed

    # --- internals ---------------------------------------------------------------------
    def _packet_id(self):
        with self._lock:
            self._next_id = self._next_id % 65535 + 1
            return self._next_id

    def _send(self, kind, body):
        data = _packet(kind, body)
        with self._lock:
            if self._closed and kind != 0xE0:
                return
            self._sock.sendall(data)
            self._last_sent = time.monotonic()

    def _read_exact(self, n):
        out = b""
        while len(out) < n:
            chunk = self._sock.recv(n - len(out))
            if not chunk:
                raise EOFError("connection closed")
            out += chunk
        return out

    def _read_packet(self):
        kind = self._read_exact(1)[0]
        return kind, self._read_rest()

    def _read_rest(self):
        """The remaining length and the rest of a packet whose first byte was read."""
        length, shift = 0, 0
        while True:
            byte = self._read_exact(1)[0]
            length += (byte & 0x7F) << shift
            shift += 7
            if not byte & 0x80:
                break
        return self._read_exact(length) if length else b""

    def _read_loop(self):
        while not self._closed:
            try:
                kind, body = self._read_packet()
            except socket.timeout:
                self._ping()
                continue
            except (OSError, EOFError) as e:
                if not self._closed:
                    _log.warning("MQTT connection to %s lost: %s", self.broker, e)
                    self._closed = True
                return
            if kind >> 4 == 3:
                self._on_publish(kind, body)
            if time.monotonic() - self._last_sent > self._keepalive / 2.0:
                self._ping()

    def _ping(self):
        try:
            self._send(0xC0, b"")
        except OSError:
            pass

    def _on_publish(self, kind, body):
        qos = (kind >> 1) & 3
        n = struct.unpack("!H", body[:2])[0]
        topic = body[2:2 + n].decode("utf-8", "replace")
        offset = 2 + n
        if qos:
            packet_id = body[offset:offset + 2]
            offset += 2
            try:
                self._send(0x40, packet_id)  # PUBACK
            except OSError:
                pass
        with self._lock:
            callbacks = list(self._callbacks.get(topic, ()))
        for callback in callbacks:
            try:
                callback(body[offset:])
            except Exception:  # a subscriber's error must not end the connection
                _log.exception('MQTT callback of topic "%s" failed', topic)


def _die_with_parent():
    """preexec_fn: SIGKILL when the process that started it dies (Linux)."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, 9)  # PR_SET_PDEATHSIG, SIGKILL
    except Exception:
        pass


def answers(host, port, timeout=0.5):
    try:
        socket.create_connection((host, port), timeout=timeout).close()
        return True
    except OSError:
        return False


class LocalBroker:
    """A mosquitto started for the run on a local address no broker answers on."""

    def __init__(self, host, port, log_file):
        self.address = "%s:%d" % (host, port)
        conf = os.path.splitext(log_file)[0] + ".conf"
        bind = "127.0.0.1" if host in ("localhost", "") else host
        with open(conf, "w") as f:
            # `user`: as root, mosquitto would switch to user "mosquitto", which clears the
            # parent-death signal that ends it with the coordinator.
            f.write("listener %d %s\nallow_anonymous true\npersistence false\nlog_dest stderr\n"
                    "user %s\n" % (port, bind, pwd.getpwuid(os.getuid()).pw_name))
        self._log = open(log_file, "ab")
        try:
            self.proc = subprocess.Popen([MOSQUITTO, "-c", conf], stdout=self._log,
                                         stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                         start_new_session=True, preexec_fn=_die_with_parent)
        except OSError as e:
            self._log.close()
            raise MqttError("cannot start %s: %s (Debian package mosquitto)"
                            % (MOSQUITTO, e.strerror or e)) from None
        deadline = time.monotonic() + 5
        while not answers(host or "127.0.0.1", port, 0.2):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise MqttError("mosquitto did not start on %s (see %s)"
                                % (self.address, log_file))
            time.sleep(0.02)

    @classmethod
    def ensure(cls, broker, log_file):
        """None if a broker answers at `broker`; a new LocalBroker if it is local and none
        answers; MqttError if it is not local and does not answer."""
        host, port = parse_broker(broker)
        if answers(host, port):
            return None
        if not is_local(host):
            raise MqttError("no MQTT broker answers at %s" % broker)
        return cls(host, port, log_file)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=3)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        self.proc.wait()
        self._log.close()
