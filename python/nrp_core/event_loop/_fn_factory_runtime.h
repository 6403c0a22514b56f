// Convoy's runtime for FN factory modules (build_fn_factory_module.sh): turns a C++ function
//   bool f(const In1* i1, ..., Out1& o1, ...)
// into a Python callable call(inputs: tuple, outputs: list) -> bool, as NRP-Core 1.4's
// FunctionalNode<tuple<In...>, tuple<Out...>> runs it:
// - an input is a pointer to the value its port last received, nullptr when it has none
//   (None on the Python side);
// - outputs live with the node: default-constructed before the first call, kept between
//   calls (the list holds them), published by the graph only when f returns true.
// Values: boost::python objects pass as they are; arithmetic types and std::string through
// boost.python's converters; std::vector of these as Python lists; any other C++ type T as
// an opaque capsule named typeid(T).name() holding a std::shared_ptr<T> (a C++ node's output
// reaches the C++ node it feeds without conversion, as NRP-Core's pointer would).
#pragma once

#include <boost/mpl/vector.hpp>
#include <boost/python.hpp>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

namespace convoy_fn_factory {
namespace bp = boost::python;

template <class T>
struct is_vector : std::false_type {};
template <class T, class A>
struct is_vector<std::vector<T, A>> : std::true_type {};

template <class T>
constexpr bool is_py = std::is_base_of_v<bp::object, T>;
template <class T>
constexpr bool is_plain = std::is_arithmetic_v<T> || std::is_same_v<T, std::string>;
template <class T>
constexpr bool is_opaque = !is_py<T> && !is_plain<T> && !is_vector<T>::value;

template <class T>
void free_capsule(PyObject* c) {
  delete static_cast<std::shared_ptr<T>*>(PyCapsule_GetPointer(c, typeid(T).name()));
}

template <class T>
bp::object box(std::shared_ptr<T> v) {
  auto* p = new std::shared_ptr<T>(std::move(v));
  PyObject* c = PyCapsule_New(p, typeid(T).name(), &free_capsule<T>);
  if (c == nullptr) {
    delete p;
    bp::throw_error_already_set();
  }
  return bp::object(bp::handle<>(c));
}

template <class T>
T* unbox(PyObject* o) {
  if (!PyCapsule_IsValid(o, typeid(T).name())) return nullptr;
  return static_cast<std::shared_ptr<T>*>(PyCapsule_GetPointer(o, typeid(T).name()))->get();
}

template <class T>
bool from_py(const bp::object& o, T& out) {
  if constexpr (std::is_same_v<T, bp::object>) {
    out = o;
    return true;
  } else if constexpr (is_py<T> || is_plain<T>) {
    bp::extract<T> e(o);
    if (!e.check()) return false;
    out = e();
    return true;
  } else if constexpr (is_vector<T>::value) {
    PyObject* p = o.ptr();
    if (!PySequence_Check(p) || PyUnicode_Check(p) || PyBytes_Check(p)) return false;
    T v;
    const auto n = bp::len(o);
    for (decltype(bp::len(o)) i = 0; i < n; ++i) {
      typename T::value_type item{};
      if (!from_py(bp::object(o[i]), item)) return false;
      v.push_back(std::move(item));
    }
    out = std::move(v);
    return true;
  } else {
    T* p = unbox<T>(o.ptr());
    if (p == nullptr) return false;
    out = *p;
    return true;
  }
}

template <class T>
bp::object to_py(const T& v) {
  if constexpr (is_py<T> || is_plain<T>) {
    return bp::object(v);
  } else if constexpr (is_vector<T>::value) {
    bp::list l;
    for (const auto& x : v) l.append(to_py(x));
    return std::move(l);
  } else {
    return box(std::make_shared<T>(v));
  }
}

inline std::string py_type(const bp::object& o) { return Py_TYPE(o.ptr())->tp_name; }

[[noreturn]] inline void bad_value(const char* fn, const char* what, const char* port,
                                   const char* type, const bp::object& o) {
  throw std::invalid_argument(std::string(what) + " \"" + port + "\" of C++ function \"" + fn +
                              "\" takes a " + type + ", got a Python " + py_type(o));
}

// One input: a pointer to its value (a copy for converted types), nullptr for None.
template <class T>
struct InSlot {
  std::optional<T> value;
  const T* ptr = nullptr;
  void set(const bp::object& o, const char* fn, const char* port, const char* type) {
    if (o.is_none()) return;
    if constexpr (is_opaque<T>) {
      ptr = unbox<T>(o.ptr());
      if (ptr == nullptr) bad_value(fn, "input", port, type, o);
    } else {
      value.emplace();
      if (!from_py(o, *value)) bad_value(fn, "input", port, type, o);
      ptr = &*value;
    }
  }
};

// One output: its value from the previous call (default-constructed at first), written by f.
template <class T>
struct OutSlot {
  T local{};
  T* opaque = nullptr;
  bp::object capsule;
  void load(const bp::object& prev, const char* fn, const char* port, const char* type) {
    if constexpr (is_opaque<T>) {
      if (prev.is_none()) {
        auto held = std::make_shared<T>();
        opaque = held.get();
        capsule = box(std::move(held));
      } else {
        opaque = unbox<T>(prev.ptr());
        if (opaque == nullptr) bad_value(fn, "output", port, type, prev);
        capsule = prev;
      }
    } else if (!prev.is_none() && !from_py(prev, local)) {
      bad_value(fn, "output", port, type, prev);
    }
  }
  T& ref() {
    if constexpr (is_opaque<T>) return *opaque;
    return local;
  }
  bp::object store() {
    if constexpr (is_opaque<T>) return capsule;
    return to_py(local);
  }
};

template <class Ins, class Outs>
struct Entry;

template <class... In, class... Out>
struct Entry<std::tuple<In...>, std::tuple<Out...>> {
  using Fn = bool (*)(const In*..., Out&...);
  struct Info {
    Fn f;
    const char* name;
    std::vector<const char*> in_names, in_types, out_names, out_types;
  };

  template <std::size_t... I, std::size_t... O>
  static bool invoke(const Info& info, const bp::tuple& ins, bp::list& outs,
                     std::index_sequence<I...>, std::index_sequence<O...>) {
    if (bp::len(ins) != sizeof...(In) || bp::len(outs) != sizeof...(Out))
      throw std::invalid_argument(std::string("C++ function \"") + info.name + "\" takes " +
                                  std::to_string(sizeof...(In)) + " inputs and " +
                                  std::to_string(sizeof...(Out)) + " outputs");
    std::tuple<InSlot<In>...> in;
    std::tuple<OutSlot<Out>...> out;
    (std::get<I>(in).set(bp::object(ins[I]), info.name, info.in_names[I], info.in_types[I]), ...);
    (std::get<O>(out).load(bp::object(outs[O]), info.name, info.out_names[O], info.out_types[O]),
     ...);
    const bool ok = info.f(std::get<I>(in).ptr..., std::get<O>(out).ref()...);
    ((outs[O] = std::get<O>(out).store()), ...);
    return ok;
  }

  // (call, input names, input type names, output names, output type names, C++ type ids)
  static bp::object make(Info info) {
    auto call = [info](bp::tuple ins, bp::list outs) -> bool {
      return invoke(info, ins, outs, std::index_sequence_for<In...>{},
                    std::index_sequence_for<Out...>{});
    };
    bp::object fn = bp::make_function(call, bp::default_call_policies(),
                                      boost::mpl::vector<bool, bp::tuple, bp::list>());
    bp::list in_names, in_types, out_names, out_types, in_ids, out_ids;
    for (auto* s : info.in_names) in_names.append(s);
    for (auto* s : info.in_types) in_types.append(s);
    for (auto* s : info.out_names) out_names.append(s);
    for (auto* s : info.out_types) out_types.append(s);
    (in_ids.append(typeid(In).name()), ...);
    (out_ids.append(typeid(Out).name()), ...);
    return bp::make_tuple(fn, in_names, in_types, out_names, out_types,
                          bp::make_tuple(in_ids, out_ids));
  }
};

}  // namespace convoy_fn_factory
