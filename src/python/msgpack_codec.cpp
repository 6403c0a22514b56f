#include "python/msgpack_codec.h"

#include <cstdint>
#include <cstring>
#include <vector>

#include "datapack/json.h"
#include "datapack/ndarray.h"

namespace convoy::python {
namespace {

constexpr int kMaxDepth = datapack::kMaxJsonDepth;

void put_be(std::string* out, uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

void put_len(std::string* out, size_t n, uint8_t fix_base, size_t fix_max, uint8_t c8, uint8_t c16,
             uint8_t c32) {
  if (fix_max && n <= fix_max) {
    out->push_back(static_cast<char>(fix_base | n));
  } else if (c8 && n <= 0xff) {
    out->push_back(static_cast<char>(c8));
    put_be(out, n, 1);
  } else if (n <= 0xffff) {
    out->push_back(static_cast<char>(c16));
    put_be(out, n, 2);
  } else {
    out->push_back(static_cast<char>(c32));
    put_be(out, n, 4);
  }
}

void put_str(std::string* out, const char* s, size_t n) {
  put_len(out, n, 0xa0, 31, 0xd9, 0xda, 0xdb);
  out->append(s, n);
}

void put_int(std::string* out, long long v) {
  if (v >= 0) {
    if (v <= 0x7f)
      out->push_back(static_cast<char>(v));
    else if (v <= 0xff) {
      out->push_back('\xcc');
      put_be(out, v, 1);
    } else if (v <= 0xffff) {
      out->push_back('\xcd');
      put_be(out, v, 2);
    } else if (v <= 0xffffffffLL) {
      out->push_back('\xce');
      put_be(out, v, 4);
    } else {
      out->push_back('\xcf');
      put_be(out, static_cast<uint64_t>(v), 8);
    }
  } else {
    if (v >= -32)
      out->push_back(static_cast<char>(v));
    else if (v >= -128) {
      out->push_back('\xd0');
      put_be(out, static_cast<uint64_t>(v), 1);
    } else if (v >= -32768) {
      out->push_back('\xd1');
      put_be(out, static_cast<uint64_t>(v), 2);
    } else if (v >= -2147483648LL) {
      out->push_back('\xd2');
      put_be(out, static_cast<uint64_t>(v), 4);
    } else {
      out->push_back('\xd3');
      put_be(out, static_cast<uint64_t>(v), 8);
    }
  }
}

bool is_ndarray(PyObject* obj) { return std::strcmp(Py_TYPE(obj)->tp_name, "numpy.ndarray") == 0; }

bool encode_ndarray(PyObject* obj, std::string* out, datapack::Builder* owner) {
  Py_buffer view;
  // C-contiguous view; non-contiguous arrays are copied by numpy into one.
  PyObject* contig = nullptr;
  if (PyObject_GetBuffer(obj, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_ND) != 0) {
    PyErr_Clear();
    contig = PyObject_CallMethod(obj, "copy", "s", "C");
    if (!contig) return false;
    if (PyObject_GetBuffer(contig, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | PyBUF_ND) != 0) {
      Py_DECREF(contig);
      return false;
    }
  }
  PyObject* dtype = PyObject_GetAttrString(obj, "dtype");
  PyObject* descr = dtype ? PyObject_GetAttrString(dtype, "str") : nullptr;
  Py_XDECREF(dtype);
  if (!descr) {
    PyBuffer_Release(&view);
    Py_XDECREF(contig);
    return false;
  }
  Py_ssize_t dlen = 0;
  const char* dstr = PyUnicode_AsUTF8AndSize(descr, &dlen);
  std::string header;
  std::vector<uint64_t> shape(view.shape, view.shape + view.ndim);
  datapack::append_ndarray_header(&header, std::string_view(dstr, static_cast<size_t>(dlen)),
                                  shape);
  if (owner && static_cast<size_t>(view.len) >= datapack::kLargeBlobBytes) {
    uint32_t index = owner->add_blob(
        std::string_view(static_cast<const char*>(view.buf), static_cast<size_t>(view.len)));
    out->push_back('\xc9');
    put_be(out, header.size() + 4, 4);
    out->push_back(static_cast<char>(datapack::kNdarrayBlobExtType));
    out->append(header);
    datapack::append_blob_index(out, index);
  } else {
    size_t total = header.size() + static_cast<size_t>(view.len);
    out->push_back('\xc9');
    put_be(out, total, 4);
    out->push_back(static_cast<char>(datapack::kNdarrayExtType));
    out->append(header);
    out->append(static_cast<const char*>(view.buf), static_cast<size_t>(view.len));
  }
  Py_DECREF(descr);
  PyBuffer_Release(&view);
  Py_XDECREF(contig);
  return true;
}

bool encode(PyObject* obj, std::string* out, datapack::Builder* owner, int depth) {
  if (depth > kMaxDepth) {
    PyErr_SetString(PyExc_ValueError, "datapack data nested too deeply (cycle?)");
    return false;
  }
  if (obj == Py_None) {
    out->push_back('\xc0');
  } else if (PyBool_Check(obj)) {
    out->push_back(obj == Py_True ? '\xc3' : '\xc2');
  } else if (PyLong_Check(obj)) {
    int overflow = 0;
    long long v = PyLong_AsLongLongAndOverflow(obj, &overflow);
    if (overflow > 0) {
      unsigned long long u = PyLong_AsUnsignedLongLong(obj);
      if (PyErr_Occurred()) return false;
      out->push_back('\xcf');
      put_be(out, u, 8);
    } else if (overflow < 0) {
      PyErr_SetString(PyExc_OverflowError, "integer below -2**63 in datapack data");
      return false;
    } else {
      put_int(out, v);
    }
  } else if (PyFloat_Check(obj)) {
    double d = PyFloat_AS_DOUBLE(obj);
    uint64_t bits;
    std::memcpy(&bits, &d, 8);
    out->push_back('\xcb');
    put_be(out, bits, 8);
  } else if (PyUnicode_Check(obj)) {
    Py_ssize_t n = 0;
    const char* s = PyUnicode_AsUTF8AndSize(obj, &n);
    if (!s) return false;
    put_str(out, s, static_cast<size_t>(n));
  } else if (PyDict_Check(obj)) {
    put_len(out, static_cast<size_t>(PyDict_GET_SIZE(obj)), 0x80, 15, 0, 0xde, 0xdf);
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (PyDict_Next(obj, &pos, &key, &value)) {
      if (PyUnicode_Check(key)) {
        if (!encode(key, out, owner, depth + 1)) return false;
      } else {
        PyObject* s = PyObject_Str(key);  // JSON keys are strings
        if (!s) return false;
        bool ok = encode(s, out, owner, depth + 1);
        Py_DECREF(s);
        if (!ok) return false;
      }
      if (!encode(value, out, owner, depth + 1)) return false;
    }
  } else if (PyList_Check(obj) || PyTuple_Check(obj)) {
    PyObject* seq = obj;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    put_len(out, static_cast<size_t>(n), 0x90, 15, 0, 0xdc, 0xdd);
    PyObject** items = PySequence_Fast_ITEMS(seq);
    for (Py_ssize_t i = 0; i < n; ++i)
      if (!encode(items[i], out, owner, depth + 1)) return false;
  } else if (PyBytes_Check(obj) || PyByteArray_Check(obj)) {
    const char* p = PyBytes_Check(obj) ? PyBytes_AS_STRING(obj) : PyByteArray_AS_STRING(obj);
    size_t n =
        static_cast<size_t>(PyBytes_Check(obj) ? PyBytes_GET_SIZE(obj) : PyByteArray_GET_SIZE(obj));
    put_len(out, n, 0, 0, 0xc4, 0xc5, 0xc6);
    out->append(p, n);
  } else if (is_ndarray(obj)) {
    return encode_ndarray(obj, out, owner);
  } else if (PyObject_HasAttrString(obj, "item") && PyObject_HasAttrString(obj, "dtype")) {
    PyObject* item = PyObject_CallMethod(obj, "item", nullptr);  // numpy scalar
    if (!item) return false;
    bool ok = encode(item, out, owner, depth + 1);
    Py_DECREF(item);
    return ok;
  } else if (PyObject_HasAttrString(obj, "keys") && PyObject_HasAttrString(obj, "__getitem__")) {
    PyObject* d =
        PyObject_CallFunctionObjArgs(reinterpret_cast<PyObject*>(&PyDict_Type), obj, nullptr);
    if (!d) return false;
    bool ok = encode(d, out, owner, depth + 1);
    Py_DECREF(d);
    return ok;
  } else {
    PyErr_Format(PyExc_TypeError, "cannot put a %s into a JSON datapack", Py_TYPE(obj)->tp_name);
    return false;
  }
  return true;
}

class Decoder {
 public:
  Decoder(std::string_view b, const datapack::View* owner)
      : p_(reinterpret_cast<const uint8_t*>(b.data())), end_(p_ + b.size()), owner_(owner) {}

  PyObject* value() {
    if (!need(1)) return nullptr;
    uint8_t c = *p_++;
    if (c <= 0x7f) return PyLong_FromLong(c);
    if (c >= 0xe0) return PyLong_FromLong(static_cast<int8_t>(c));
    if ((c & 0xf0) == 0x80) return map(c & 0x0f);
    if ((c & 0xf0) == 0x90) return array(c & 0x0f);
    if ((c & 0xe0) == 0xa0) return str(c & 0x1f);
    switch (c) {
      case 0xc0:
        Py_RETURN_NONE;
      case 0xc2:
        Py_RETURN_FALSE;
      case 0xc3:
        Py_RETURN_TRUE;
      case 0xc4:
        return bin(be(1));
      case 0xc5:
        return bin(be(2));
      case 0xc6:
        return bin(be(4));
      case 0xc7: {
        size_t n = be(1);
        return ext(n);
      }
      case 0xc8: {
        size_t n = be(2);
        return ext(n);
      }
      case 0xc9: {
        size_t n = be(4);
        return ext(n);
      }
      case 0xca: {
        uint32_t bits = static_cast<uint32_t>(be(4));
        float f;
        std::memcpy(&f, &bits, 4);
        return ok_ ? PyFloat_FromDouble(f) : nullptr;
      }
      case 0xcb: {
        uint64_t bits = be(8);
        double d;
        std::memcpy(&d, &bits, 8);
        return ok_ ? PyFloat_FromDouble(d) : nullptr;
      }
      case 0xcc:
        return uint(be(1));
      case 0xcd:
        return uint(be(2));
      case 0xce:
        return uint(be(4));
      case 0xcf:
        return uint(be(8));
      case 0xd0:
        return sint(static_cast<int8_t>(be(1)));
      case 0xd1:
        return sint(static_cast<int16_t>(be(2)));
      case 0xd2:
        return sint(static_cast<int32_t>(be(4)));
      case 0xd3:
        return sint(static_cast<int64_t>(be(8)));
      case 0xd4:
        return ext(1);
      case 0xd5:
        return ext(2);
      case 0xd6:
        return ext(4);
      case 0xd7:
        return ext(8);
      case 0xd8:
        return ext(16);
      case 0xd9:
        return str(be(1));
      case 0xda:
        return str(be(2));
      case 0xdb:
        return str(be(4));
      case 0xdc:
        return array(be(2));
      case 0xdd:
        return array(be(4));
      case 0xde:
        return map(be(2));
      case 0xdf:
        return map(be(4));
      default:
        return fail("unknown MessagePack type byte");
    }
  }
  bool at_end() const { return p_ == end_; }

 private:
  PyObject* fail(const char* what) {
    if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, what);
    ok_ = false;
    return nullptr;
  }
  bool need(size_t n) {
    if (static_cast<size_t>(end_ - p_) < n) {
      fail("truncated MessagePack data");
      return false;
    }
    return true;
  }
  uint64_t be(int n) {
    if (!need(n)) return 0;
    uint64_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | *p_++;
    return v;
  }
  PyObject* uint(uint64_t v) { return ok_ ? PyLong_FromUnsignedLongLong(v) : nullptr; }
  PyObject* sint(int64_t v) { return ok_ ? PyLong_FromLongLong(v) : nullptr; }
  PyObject* str(size_t n) {
    if (!ok_ || !need(n)) return nullptr;
    PyObject* s = PyUnicode_DecodeUTF8(reinterpret_cast<const char*>(p_), n, "strict");
    p_ += n;
    return s;
  }
  PyObject* bin(size_t n) {
    if (!ok_ || !need(n)) return nullptr;
    PyObject* b = PyBytes_FromStringAndSize(reinterpret_cast<const char*>(p_), n);
    p_ += n;
    return b;
  }
  // Each item takes a byte at least: a count larger than what is left is truncated data,
  // found before allocating for it. Nesting is bounded as in encode(), so that hostile data
  // cannot overflow the stack.
  bool open_container(size_t items) {
    if (static_cast<size_t>(end_ - p_) < items) {
      fail("truncated MessagePack data");
      return false;
    }
    if (depth_ >= kMaxDepth) {
      fail("MessagePack data nested too deeply");
      return false;
    }
    ++depth_;
    return true;
  }
  PyObject* array(size_t n) {
    if (!ok_ || !open_container(n)) return nullptr;
    return close_container(array_items(n));
  }
  PyObject* close_container(PyObject* value) {
    --depth_;
    return value;
  }
  PyObject* array_items(size_t n) {
    PyObject* list = PyList_New(static_cast<Py_ssize_t>(n));
    if (!list) return nullptr;
    for (size_t i = 0; i < n; ++i) {
      PyObject* v = value();
      if (!v) {
        Py_DECREF(list);
        return nullptr;
      }
      PyList_SET_ITEM(list, static_cast<Py_ssize_t>(i), v);
    }
    return list;
  }
  PyObject* map(size_t n) {
    if (!ok_ || !open_container(n)) return nullptr;
    return close_container(map_items(n));
  }
  PyObject* map_items(size_t n) {
    PyObject* dict = PyDict_New();
    if (!dict) return nullptr;
    for (size_t i = 0; i < n; ++i) {
      PyObject* k = value();
      PyObject* v = k ? value() : nullptr;
      if (!v || PyDict_SetItem(dict, k, v) != 0) {
        Py_XDECREF(k);
        Py_XDECREF(v);
        Py_DECREF(dict);
        return nullptr;
      }
      Py_DECREF(k);
      Py_DECREF(v);
    }
    return dict;
  }
  PyObject* ext(size_t n) {
    if (!ok_ || !need(n + 1)) return nullptr;
    int8_t type = static_cast<int8_t>(*p_++);
    const uint8_t* body = p_;
    p_ += n;
    if (type == datapack::kNdarrayExtType || type == datapack::kNdarrayBlobExtType) {
      return ndarray(body, n, type == datapack::kNdarrayBlobExtType);
    }
    return PyBytes_FromStringAndSize(reinterpret_cast<const char*>(body), n);
  }
  PyObject* ndarray(const uint8_t* b, size_t n, bool in_blob);

  const uint8_t* p_;
  const uint8_t* end_;
  const datapack::View* owner_;
  bool ok_ = true;
  int depth_ = 0;
};

PyObject* Decoder::ndarray(const uint8_t* b, size_t n, bool in_blob) {
  datapack::NdarrayHeader header;
  std::string_view data;
  try {
    data = datapack::parse_ndarray_header({reinterpret_cast<const char*>(b), n}, &header);
    if (in_blob) {
      if (!owner_) return fail("array blob reference without its datapack");
      data = owner_->blob(datapack::parse_blob_index(data));
    }
  } catch (const std::exception& ex) {
    return fail(ex.what());
  }
  // Plain data only: an object array would be built from pointers off the wire.
  const size_t item = datapack::dtype_size(header.dtype);
  if (item == 0) return fail("numpy array dtype is not plain data (object or structured)");
  uint64_t count = 1;
  for (uint64_t d : header.shape) {
    if (d != 0 && count > UINT64_MAX / d) return fail("numpy array shape overflows");
    count *= d;
  }
  if (count > UINT64_MAX / item || count * item != data.size())
    return fail("ndarray size does not match its shape");
  PyObject* shape = PyTuple_New(static_cast<Py_ssize_t>(header.shape.size()));
  for (size_t i = 0; i < header.shape.size(); ++i)
    PyTuple_SET_ITEM(shape, static_cast<Py_ssize_t>(i),
                     PyLong_FromUnsignedLongLong(header.shape[i]));
  static PyObject* numpy_empty = nullptr;
  if (!numpy_empty) {
    PyObject* np = PyImport_ImportModule("numpy");
    if (!np) {
      Py_DECREF(shape);
      return fail("numpy is needed to decode an array");
    }
    numpy_empty = PyObject_GetAttrString(np, "empty");
    Py_DECREF(np);
  }
  PyObject* arr = PyObject_CallFunction(numpy_empty, "Os", shape, header.dtype.c_str());
  Py_DECREF(shape);
  if (!arr) return fail("bad ndarray dtype");
  Py_buffer view;
  if (PyObject_GetBuffer(arr, &view, PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE) != 0) {
    Py_DECREF(arr);
    return fail("ndarray buffer");
  }
  if (static_cast<size_t>(view.len) != data.size()) {
    PyBuffer_Release(&view);
    Py_DECREF(arr);
    return fail("ndarray size does not match its shape");
  }
  if (!data.empty()) std::memcpy(view.buf, data.data(), data.size());  // empty: data() may be null
  datapack::count_copy(data.size());
  PyBuffer_Release(&view);
  return arr;
}

}  // namespace

bool msgpack_encode(PyObject* obj, std::string* out, datapack::Builder* blob_owner) {
  return encode(obj, out, blob_owner, 0);
}

PyObject* msgpack_decode(std::string_view bytes, const datapack::View* blob_owner) {
  Decoder d(bytes, blob_owner);
  PyObject* v = d.value();
  if (v && !d.at_end()) {
    Py_DECREF(v);
    PyErr_SetString(PyExc_ValueError, "trailing bytes after MessagePack value");
    return nullptr;
  }
  return v;
}

}  // namespace convoy::python
