// Force-included into every translation unit of the WASM build (scripts/build-wasm): what Debian's
// Emscripten 3.1.6 (libc++ 14) lacks of the C++20 library that codec/ uses. Empty once the library has it.
#pragma once

#include <bit>
#include <type_traits>

#ifndef __cpp_lib_bit_cast
namespace std {
template <class To, class From>
requires(sizeof(To) == sizeof(From) && is_trivially_copyable_v<To> &&
         is_trivially_copyable_v<From>) constexpr To bit_cast(const From& from) noexcept {
  return __builtin_bit_cast(To, from);
}
}  // namespace std
#endif
