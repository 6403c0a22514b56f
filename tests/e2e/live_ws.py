"""A small Foxglove WebSocket client (subprotocol foxglove.websocket.v1) in plain Python for the
live tests that need to publish (clientPublish: /convoy/control) and to time what they get:
RFC 6455 framing over a socket, a reader thread that keeps every message it gets."""
import base64
import json
import os
import socket
import struct
import threading
import time

SUBPROTOCOL = "foxglove.websocket.v1"


class LiveClient:
    def __init__(self, port, host="127.0.0.1", wait_s=30.0):
        deadline = time.time() + wait_s
        while True:
            try:
                self.sock = socket.create_connection((host, port), timeout=5)
                self._handshake(host, port)
                break
            except (OSError, ConnectionError):
                if time.time() > deadline:
                    raise
                time.sleep(0.05)
        self.sock.settimeout(None)
        self.lock = threading.Condition()
        self.server_info = None
        self.channels = {}       # topic -> channel
        self.status = []         # status messages (op "status")
        self.data = {}           # subscription id -> [(receive time ns, payload bytes)]
        self.times = []          # the time messages (ns)
        self.closed = False
        self._next_sub = 1
        self._subs = {}          # topic -> subscription id
        self._send_lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()

    def _handshake(self, host, port):
        key = base64.b64encode(os.urandom(16)).decode()
        req = ("GET / HTTP/1.1\r\nHost: %s:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n"
               "Sec-WebSocket-Protocol: %s\r\n\r\n" % (host, port, key, SUBPROTOCOL))
        self.sock.sendall(req.encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(1)
            if not chunk:
                raise ConnectionError("closed during the handshake")
            head += chunk
        if not head.startswith(b"HTTP/1.1 101"):
            raise ConnectionError("handshake refused: %r" % head[:80])

    def _recv_exact(self, n):
        out = b""
        while len(out) < n:
            chunk = self.sock.recv(n - len(out))
            if not chunk:
                raise ConnectionError("closed")
            out += chunk
        return out

    def _read(self):
        try:
            message, kind = b"", None
            while True:
                b0, b1 = self._recv_exact(2)
                opcode, fin = b0 & 0x0F, b0 & 0x80
                n = b1 & 0x7F
                if n == 126:
                    n = struct.unpack(">H", self._recv_exact(2))[0]
                elif n == 127:
                    n = struct.unpack(">Q", self._recv_exact(8))[0]
                payload = self._recv_exact(n)
                if opcode == 8:
                    break
                if opcode == 9:
                    self._send_frame(10, payload)
                    continue
                if opcode in (1, 2):
                    message, kind = payload, opcode
                elif opcode == 0:
                    message += payload
                if fin and kind is not None:
                    self._on_message(kind, message)
                    message, kind = b"", None
        except (OSError, ConnectionError, ValueError):
            pass
        with self.lock:
            self.closed = True
            self.lock.notify_all()

    def _on_message(self, kind, payload):
        with self.lock:
            if kind == 1:
                msg = json.loads(payload)
                op = msg.get("op")
                if op == "serverInfo":
                    self.server_info = msg
                elif op == "advertise":
                    for c in msg["channels"]:
                        self.channels[c["topic"]] = c
                elif op == "status":
                    self.status.append(msg)
            elif payload[:1] == b"\x01":
                sub, t = struct.unpack_from("<IQ", payload, 1)
                self.data.setdefault(sub, []).append((t, payload[13:]))
            elif payload[:1] == b"\x02":
                self.times.append(struct.unpack_from("<Q", payload, 1)[0])
            self.lock.notify_all()

    def _send_frame(self, opcode, payload):
        mask = os.urandom(4)
        n = len(payload)
        head = bytes([0x80 | opcode])
        if n < 126:
            head += bytes([0x80 | n])
        elif n < 65536:
            head += bytes([0x80 | 126]) + struct.pack(">H", n)
        else:
            head += bytes([0x80 | 127]) + struct.pack(">Q", n)
        body = bytes(b ^ mask[i % 4] for i, b in enumerate(payload))
        with self._send_lock:
            self.sock.sendall(head + mask + body)

    def send_json(self, obj):
        self._send_frame(1, json.dumps(obj).encode())

    def send_binary(self, data):
        self._send_frame(2, data)

    def wait_for(self, pred, timeout=10.0):
        """Waits until pred() (called under the lock) is true; its value, or None."""
        deadline = time.time() + timeout
        with self.lock:
            while True:
                v = pred()
                if v or self.closed or time.time() > deadline:
                    return v
                self.lock.wait(0.05)

    def subscribe(self, topic, timeout=10.0):
        if not self.wait_for(lambda: topic in self.channels, timeout):
            raise AssertionError("no channel %s (got %s)" % (topic, sorted(self.channels)))
        sub = self._next_sub
        self._next_sub += 1
        self._subs[topic] = sub
        self.send_json({"op": "subscribe",
                        "subscriptions": [{"id": sub, "channelId": self.channels[topic]["id"]}]})
        return sub

    def messages(self, topic):
        """The JSON messages got on a subscribed topic so far."""
        with self.lock:
            return [json.loads(p) for _, p in self.data.get(self._subs[topic], [])]

    def advertise(self, channel_id, topic, encoding="json", schema_name="convoy.Control"):
        self.send_json({"op": "advertise", "channels": [
            {"id": channel_id, "topic": topic, "encoding": encoding, "schemaName": schema_name}]})

    def publish(self, channel_id, obj):
        payload = obj if isinstance(obj, bytes) else json.dumps(obj).encode()
        self.send_binary(b"\x01" + struct.pack("<I", channel_id) + payload)

    def last_time(self):
        with self.lock:
            return self.times[-1] if self.times else None

    def close(self):
        try:
            self._send_frame(8, b"")
            self.sock.close()
        except OSError:
            pass
