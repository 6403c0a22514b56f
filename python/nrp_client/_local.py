"""The client side of NRPCoreSim's local channel (`--local_socket PATH`,
src/transport/local_rpc.h): the gRPC service's calls as frames on a Unix socket.

A frame is a 4-byte little-endian length, then that many bytes. A request is one byte naming
the method (its index in METHODS), then the request message; the reply is one byte of gRPC
status code (0: OK), then the reply message or the error text. Errors are raised as
grpc.RpcError with code() and details(), as a gRPC call's are, so that callers handle both
alike."""
import os
import socket
import struct
import threading
import time

import grpc

METHODS = ("initialize", "runLoop", "runUntilTimeout", "stopLoop", "reset", "shutdown",
           "describeType")
_CODES = {c.value[0]: c for c in grpc.StatusCode}
_LEN = struct.Struct("<I")


class LocalRpcError(grpc.RpcError):
    def __init__(self, code, details):
        super().__init__(details)
        self._code, self._details = code, details

    def code(self):
        return self._code

    def details(self):
        return self._details


class LocalChannel:
    """One connection to the server's local socket; calls from several threads take turns."""

    def __init__(self, path, timeout_s, alive):
        """Connects to `path`, retrying for `timeout_s` while alive() (the server starts its
        local socket right after its gRPC port)."""
        deadline = time.monotonic() + timeout_s
        while True:
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                sock.connect(path)
                break
            except OSError as e:
                sock.close()
                if not alive() or time.monotonic() > deadline:
                    raise ConnectionError("NRPCoreSim's local socket %s: %s" % (path, e)) from None
                time.sleep(0.005)
        self._sock = sock
        self._lock = threading.Lock()
        self._buffer = bytearray(1 << 16)  # what _receive() has read (grown for larger frames)
        self._view = memoryview(self._buffer)
        self._have = 0  # bytes of it read and not yet returned

    def callable(self, method, response_class):
        index = bytes([METHODS.index(method)])

        def call(request, timeout=None):
            payload = self._call(index + _serialized(request))
            return response_class.FromString(payload)
        return call

    def begin(self, method, request):
        """Sends a call without waiting for its reply: finish() receives it. Meanwhile, this
        channel takes no other call (begin() holds the channel until finish()), so that one
        thread can have calls to several servers in flight at once."""
        self._lock.acquire()
        try:
            self._send(bytes([METHODS.index(method)]) + _serialized(request))
        except BaseException:
            self._lock.release()
            raise

    def finish(self, response_class):
        """The reply to the call begin() sent (raises its error as _call does)."""
        try:
            reply = self._receive()
        finally:
            self._lock.release()
        return response_class.FromString(self._payload(reply))

    def close(self):
        sock, self._sock = self._sock, None
        if sock is not None:
            sock.close()

    def _call(self, frame):
        with self._lock:
            self._send(frame)
            reply = self._receive()
        return self._payload(reply)

    def _send(self, frame):
        if self._sock is None:
            raise LocalRpcError(grpc.StatusCode.UNAVAILABLE, "the local channel is closed")
        try:
            self._sock.sendall(_LEN.pack(len(frame)) + frame)
        except OSError as e:
            raise LocalRpcError(grpc.StatusCode.UNAVAILABLE, "local socket: %s" % e) from None

    def _receive(self):
        if self._sock is None:
            raise LocalRpcError(grpc.StatusCode.UNAVAILABLE, "the local channel is closed")
        try:
            return self._frame()
        except OSError as e:
            raise LocalRpcError(grpc.StatusCode.UNAVAILABLE, "local socket: %s" % e) from None

    @staticmethod
    def _payload(reply):
        """The reply's message bytes, or its error raised."""
        if not reply:
            raise LocalRpcError(grpc.StatusCode.INTERNAL, "an empty reply from the server")
        if reply[0] != 0:
            code = _CODES.get(reply[0], grpc.StatusCode.UNKNOWN)
            raise LocalRpcError(code, reply[1:].decode("utf-8", "replace"))
        return reply[1:]

    def _frame(self):
        """The next frame's bytes, read in as few calls as the socket allows (usually one:
        the length and the reply together)."""
        while True:
            have = self._have
            if have >= 4:
                end = 4 + _LEN.unpack_from(self._buffer)[0]
                if have >= end:
                    frame = bytes(self._view[4:end])
                    if have > end:  # the start of a next frame (the server sends none unasked)
                        rest = bytes(self._view[end:have])
                        self._buffer[:len(rest)] = rest
                    self._have = have - end
                    return frame
                if end > len(self._buffer):
                    self._view.release()
                    self._buffer = self._buffer[:have] + bytearray(end - have)
                    self._view = memoryview(self._buffer)
            k = self._sock.recv_into(self._view[have:])
            if k == 0:
                raise OSError("the server closed the connection")
            self._have = have + k


def _serialized(request):
    """A request's bytes: bytes as they are (nrp_client's _wire), else the message's."""
    return request if isinstance(request, bytes) else request.SerializeToString()


def socket_path(folder):
    return os.path.join(folder, "nrp.sock")
