"""A local mosquitto broker and a minimal MQTT 3.1.1 subscriber, for the data-transfer tests.

`Broker` starts /usr/sbin/mosquitto (Debian's `mosquitto` package) in the foreground on a free
loopback port with a config of its own in a temp folder, and kills it when stopped. No daemon,
no system config. `Subscriber` speaks just enough MQTT over a socket to subscribe to a filter
and record what arrives (python3-paho-mqtt and mosquitto-clients are not needed).
"""

import os
import shutil
import socket
import struct
import subprocess
import tempfile
import threading
import time

from e2e_util import free_port

MOSQUITTO = "/usr/sbin/mosquitto"


class Broker:
    def __init__(self):
        self.dir = tempfile.mkdtemp(prefix="convoy-mosquitto-")
        self.port = free_port()
        self.conf = os.path.join(self.dir, "mosquitto.conf")
        with open(self.conf, "w") as f:
            f.write("listener %d 127.0.0.1\nallow_anonymous true\npersistence false\n"
                    "log_dest stderr\n" % self.port)
        self.log = open(os.path.join(self.dir, "mosquitto.log"), "w+")
        self.proc = subprocess.Popen([MOSQUITTO, "-c", self.conf], stdout=self.log,
                                     stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        deadline = time.monotonic() + 10
        while True:
            if self.proc.poll() is not None:
                raise RuntimeError("mosquitto exited at start: " + self.log_text())
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=0.2).close()
                break
            except OSError:
                if time.monotonic() > deadline:
                    self.stop()
                    raise RuntimeError("mosquitto does not listen on %d: %s"
                                       % (self.port, self.log_text()))
                time.sleep(0.02)

    @property
    def address(self):
        return "localhost:%d" % self.port

    def log_text(self):
        self.log.flush()
        with open(self.log.name) as f:
            return f.read()

    def stop(self):
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        self.log.close()
        shutil.rmtree(self.dir, ignore_errors=True)


def _remaining_length(n):
    out = bytearray()
    while True:
        b, n = n % 128, n // 128
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def _utf8(s):
    b = s.encode()
    return struct.pack(">H", len(b)) + b


class Subscriber:
    """Subscribes to `topic_filter` (QoS 1) and records (topic, payload bytes, retain flag)."""

    def __init__(self, port, topic_filter="#", client_id="convoy-test-sub"):
        self.messages = []
        self._lock = threading.Lock()
        self._sock = socket.create_connection(("127.0.0.1", port), timeout=5)
        body = _utf8("MQTT") + bytes([4, 0x02]) + struct.pack(">H", 60) + _utf8(client_id)
        self._sock.sendall(b"\x10" + _remaining_length(len(body)) + body)
        kind, payload = self._read_packet()
        if kind != 2 or payload[1] != 0:
            raise RuntimeError("CONNACK refused: %r" % payload)
        body = struct.pack(">H", 1) + _utf8(topic_filter) + b"\x01"
        self._sock.sendall(b"\x82" + _remaining_length(len(body)) + body)
        kind, payload = self._read_packet()
        if kind != 9:
            raise RuntimeError("no SUBACK")
        self._sock.settimeout(0.1)
        self._stop = False
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _read_exact(self, n):
        data = b""
        while len(data) < n:
            chunk = self._sock.recv(n - len(data))
            if not chunk:
                raise EOFError
            data += chunk
        return data

    def _read_packet(self):
        first = self._read_exact(1)[0]
        length, shift = 0, 0
        while True:
            b = self._read_exact(1)[0]
            length |= (b & 0x7F) << shift
            shift += 7
            if not b & 0x80:
                break
        return first >> 4, self._read_exact(length)

    def _run(self):
        while not self._stop:
            try:
                first = self._sock.recv(1)
            except socket.timeout:
                continue
            except OSError:
                return
            if not first:
                return
            self._sock.settimeout(5)
            try:
                length, shift = 0, 0
                while True:
                    b = self._read_exact(1)[0]
                    length |= (b & 0x7F) << shift
                    shift += 7
                    if not b & 0x80:
                        break
                body = self._read_exact(length)
            finally:
                self._sock.settimeout(0.1)
            kind, flags = first[0] >> 4, first[0] & 0x0F
            if kind != 3:
                continue
            n = struct.unpack(">H", body[:2])[0]
            topic = body[2:2 + n].decode()
            rest = body[2 + n:]
            qos = (flags >> 1) & 3
            if qos:
                packet_id, rest = rest[:2], rest[2:]
                self._sock.sendall(b"\x40\x02" + packet_id)  # PUBACK
            with self._lock:
                self.messages.append((topic, bytes(rest), bool(flags & 1)))

    def wait_for(self, predicate, timeout=5.0):
        """Waits until predicate(messages) is true; returns the messages either way."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self._lock:
                if predicate(list(self.messages)):
                    break
            time.sleep(0.02)
        with self._lock:
            return list(self.messages)

    def on(self, topic):
        with self._lock:
            return [m[1] for m in self.messages if m[0] == topic]

    def close(self):
        self._stop = True
        self._thread.join(2)
        try:
            self._sock.sendall(b"\xe0\x00")  # DISCONNECT
        except OSError:
            pass
        self._sock.close()
