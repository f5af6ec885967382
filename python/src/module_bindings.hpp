#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include "vrflow/module/module.hpp"

// The pieces of the `vrflow._module` extension (docs/python.md), bound by module_main.cpp.

namespace vrflow::python {

/// A user's mistake reported to Python as vrflow.Error (a RuntimeError).
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A parameter read that the manifest does not allow, reported as vrflow.ParameterError.
struct ParameterError : Error {
  using Error::Error;
};

/// A NumPy array of `count` elements of T viewing `bytes` in place (no copy), kept alive by
/// `owner`; read-only unless `writable`.
template <typename T>
pybind11::array viewOf(const void* data, std::size_t count, const pybind11::object& owner,
                       bool writable = false) {
  pybind11::array array(pybind11::dtype::of<T>(), {static_cast<pybind11::ssize_t>(count)},
                        {static_cast<pybind11::ssize_t>(sizeof(T))}, data, owner);
  if (!writable) array.attr("setflags")(pybind11::arg("write") = false);
  return array;
}

/// A read-only uint8 view of `bytes`, kept alive by `owner`.
inline pybind11::array byteView(std::span<const std::byte> bytes, const pybind11::object& owner) {
  return viewOf<std::uint8_t>(bytes.data(), bytes.size(), owner);
}

/// A message being built in shared memory (Python's OutgoingMessage): empty once sent or
/// sealed.
struct Outgoing {
  std::optional<OutgoingMessage> message;
  /// Where the message began when new_raw_resource() last handed out a writable view.
  const std::byte* viewBase = nullptr;
  /// The builder; raises vrflow.Error once the message was sent or sealed.
  msg::MessageBuilder& builder();
  /// Raises vrflow.Error when the message moved (it grew) after a writable view was handed out:
  /// that view then points at the old place.
  void checkViewsStayed();
};

/// Binds Message, Chunk and the typed chunk views (module_messages.cpp).
void bindMessages(pybind11::module_& m);
/// Binds OutgoingMessage and ObjectWriter (module_builder.cpp).
void bindBuilder(pybind11::module_& m);
/// Binds Module and its ports (module_module.cpp).
void bindModule(pybind11::module_& m);

}  // namespace vrflow::python
