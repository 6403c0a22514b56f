#include "python/msgpack_codec.h"

#include <gtest/gtest.h>

#include <vector>

#include "datapack/ndarray.h"
#include "python/interpreter.h"

using namespace pybind11::literals;

namespace convoy::python {
namespace {

class MsgpackCodec : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { interpreter_ = new Interpreter(); }
  static void TearDownTestSuite() {
    delete interpreter_;
    interpreter_ = nullptr;
  }
  static py::object roundtrip(py::handle obj) {
    std::string bytes;
    if (!msgpack_encode(obj.ptr(), &bytes)) throw py::error_already_set();
    PyObject* v = msgpack_decode(bytes);
    if (!v) throw py::error_already_set();
    return py::reinterpret_steal<py::object>(v);
  }
  static Interpreter* interpreter_;
};
Interpreter* MsgpackCodec::interpreter_ = nullptr;

TEST_F(MsgpackCodec, JsonValuesRoundTrip) {
  py::object v = py::eval(
      "{'a': 1, 'neg': -5, 'big': 2**63 + 7, 'small': -2**62, 'f': 0.1, 's': 'é' * 40,"
      " 'l': [None, True, False, [1, 2.5]], 'b': b'\\x00\\x01', 'd': {'x': {'y': []}},"
      " 'n': list(range(70000))}");
  EXPECT_TRUE(roundtrip(v).equal(v));
}

TEST_F(MsgpackCodec, TuplesBecomeListsAndKeysStrings) {
  py::object v = py::eval("{1: (1, 2)}");
  EXPECT_TRUE(roundtrip(v).equal(py::eval("{'1': [1, 2]}")));
}

TEST_F(MsgpackCodec, NumpyArraysKeepDtypeAndShape) {
  py::module_ np = py::module_::import("numpy");
  py::object a = np.attr("arange")(60, "dtype"_a = "float32").attr("reshape")(3, 4, 5);
  py::object back = roundtrip(a);
  EXPECT_EQ(py::str(back.attr("dtype")).cast<std::string>(), "float32");
  EXPECT_TRUE(py::object(back.attr("shape")).equal(py::make_tuple(3, 4, 5)));
  EXPECT_TRUE(np.attr("array_equal")(a, back).cast<bool>());
  // A transposed (non-contiguous) view is sent in C order.
  py::object t = a.attr("T");
  EXPECT_TRUE(np.attr("array_equal")(t, roundtrip(t)).cast<bool>());
  // The encoding is the raw bytes plus a small header, not a list of numbers.
  std::string bytes;
  ASSERT_TRUE(msgpack_encode(a.ptr(), &bytes));
  EXPECT_LT(bytes.size(), 60 * 4 + 64u);
}

// An inline numpy array (MessagePack ext 8, type 1) with the given header and data bytes.
std::string ndarray_ext(std::string_view dtype, std::vector<uint64_t> shape, std::string data) {
  std::string body;
  datapack::append_ndarray_header(&body, dtype, shape);
  body += data;
  std::string out = {'\xc7', static_cast<char>(body.size()), datapack::kNdarrayExtType};
  return out + body;
}

// An array from the wire is plain data only: an object array's bytes would be taken as
// pointers. A forged header whose shape does not match its bytes is refused too.
TEST_F(MsgpackCodec, ObjectArraysAndForgedShapesAreRefused) {
  const std::string two_pointers(16, '\x41');
  const uint64_t wraps = uint64_t{1} << 62;  // x 4 wraps to 0 elements of 8 bytes
  for (const std::string& bytes :
       {ndarray_ext("|O8", {2}, two_pointers), ndarray_ext("<f8", {wraps, 4}, "")}) {
    EXPECT_EQ(msgpack_decode(bytes), nullptr);
    ASSERT_TRUE(PyErr_Occurred());
    PyErr_Clear();
  }
}

TEST_F(MsgpackCodec, UnsupportedTypeRaisesTypeError) {
  py::object v = py::eval("{'f': object()}");
  std::string bytes;
  EXPECT_FALSE(msgpack_encode(v.ptr(), &bytes));
  ASSERT_TRUE(PyErr_ExceptionMatches(PyExc_TypeError));
  PyErr_Clear();
}

TEST_F(MsgpackCodec, TruncatedInputRaises) {
  EXPECT_EQ(msgpack_decode(std::string_view("\x92\x01", 2)), nullptr);
  PyErr_Clear();
}

// Found by fuzz/python_codec: the shape was handed to numpy.empty before it was compared with
// the data, so a header of a few bytes allocated tens of GB.
TEST_F(MsgpackCodec, ArrayHeaderLargerThanItsDataIsRejectedBeforeAllocating) {
  for (std::vector<uint64_t> shape : {std::vector<uint64_t>{1u << 20, 1u << 20},
                                      std::vector<uint64_t>{~0ull, 2}, std::vector<uint64_t>{3}}) {
    EXPECT_EQ(msgpack_decode(ndarray_ext("<f8", shape, std::string(16, '\0'))), nullptr);
    ASSERT_TRUE(PyErr_ExceptionMatches(PyExc_ValueError));
    PyErr_Clear();
  }
  PyObject* ok = msgpack_decode(ndarray_ext("<f8", {2}, std::string(16, '\0')));
  ASSERT_NE(ok, nullptr);
  Py_DECREF(ok);
}

// Hostile containers: nesting that would overflow the stack, counts larger than the data.
TEST_F(MsgpackCodec, DeepNestingAndHugeCountsAreRefused) {
  const std::string deep = std::string(100'000, '\x91') + '\xc0';
  EXPECT_EQ(msgpack_decode(deep), nullptr);
  ASSERT_TRUE(PyErr_ExceptionMatches(PyExc_ValueError));
  PyErr_Clear();
  for (std::string_view huge : {std::string_view("\xdd\xff\xff\xff\xff\xc0", 6),
                                std::string_view("\xdf\xff\xff\xff\xff\xc0", 6)}) {
    EXPECT_EQ(msgpack_decode(huge), nullptr);
    ASSERT_TRUE(PyErr_ExceptionMatches(PyExc_ValueError));
    PyErr_Clear();
  }
  // As deep as encode() writes (200 levels) still decodes; one more does not.
  py::object v = py::none();
  for (int i = 0; i < 200; ++i) v = py::list(py::make_tuple(v));
  EXPECT_TRUE(roundtrip(v).equal(v));
  EXPECT_EQ(msgpack_decode(std::string(201, '\x91') + '\xc0'), nullptr);
  PyErr_Clear();
}

}  // namespace
}  // namespace convoy::python
