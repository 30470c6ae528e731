// Internal invariant checks in the manner of pbrt-v4's util/check.h: a failed check reports
// both operands. They throw std::logic_error instead of aborting, because this library runs
// inside Blender, where an abort would end the artist's session.
// User input is validated at the API boundary with std::invalid_argument (see aolab.h);
// these checks are for conditions that only a bug in AO Lab can violate.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace aolab::detail {

template <class A, class B>
[[noreturn]] void check_failed(const char* file, int line, const char* a_expr, const char* op,
                               const char* b_expr, const A& a, const B& b) {
  std::ostringstream s;
  s << file << ':' << line << ": internal check failed: " << a_expr << ' ' << op << ' ' << b_expr
    << " with " << a_expr << " = " << a << ", " << b_expr << " = " << b;
  throw std::logic_error(s.str());
}

}  // namespace aolab::detail

#define AOLAB_CHECK_OP(a, op, b)                                                          \
  do {                                                                                    \
    const auto& aolab_a_ = (a);                                                           \
    const auto& aolab_b_ = (b);                                                           \
    if (!(aolab_a_ op aolab_b_))                                                          \
      ::aolab::detail::check_failed(__FILE__, __LINE__, #a, #op, #b, aolab_a_, aolab_b_); \
  } while (false)

#define CHECK_EQ(a, b) AOLAB_CHECK_OP(a, ==, b)
#define CHECK_NE(a, b) AOLAB_CHECK_OP(a, !=, b)
#define CHECK_LT(a, b) AOLAB_CHECK_OP(a, <, b)
#define CHECK_LE(a, b) AOLAB_CHECK_OP(a, <=, b)
#define CHECK_GT(a, b) AOLAB_CHECK_OP(a, >, b)
#define CHECK_GE(a, b) AOLAB_CHECK_OP(a, >=, b)

// Debug-only variants for hot loops.
#ifdef NDEBUG
#define DCHECK_LT(a, b) ((void)0)
#define DCHECK_LE(a, b) ((void)0)
#define DCHECK_GE(a, b) ((void)0)
#else
#define DCHECK_LT(a, b) CHECK_LT(a, b)
#define DCHECK_LE(a, b) CHECK_LE(a, b)
#define DCHECK_GE(a, b) CHECK_GE(a, b)
#endif

namespace aolab {

namespace detail {
/// `v` in %g style with as few significant digits as read back as exactly `v` (at least 6,
/// as std::ostream prints, at most 9 for a float and 17 for a double): 0.5 stays "0.5" and
/// 1e+30 stays "1e+30", while 2147483648 is "2147483648", never "2.14748e+09", so a value
/// and the bound it breaks never print alike. NaN and infinities print as "nan", "inf".
template <class T>
std::string exact_number(T v) {
  static_assert(std::is_floating_point_v<T>);
  constexpr int kMaxDigits = std::is_same_v<T, float> ? 9 : 17;
  char buf[64];
  for (int digits = 6;; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, double(v));
    if (digits >= kMaxDigits || v != v) break;
    const T back =
        std::is_same_v<T, float> ? T(std::strtof(buf, nullptr)) : T(std::strtod(buf, nullptr));
    if (back == v) break;
  }
  return buf;
}
}  // namespace detail

/// Throws std::invalid_argument("<parameter> <requirement>, got <value>"): the one way user
/// input is rejected, so every message names the parameter and the offending value. A
/// floating-point value is printed with enough digits to read back exactly
/// (detail::exact_number), an integer exactly.
template <class V>
[[noreturn]] void throw_invalid(const std::string& parameter, const std::string& requirement,
                                const V& value) {
  std::ostringstream s;
  s << parameter << ' ' << requirement << ", got ";
  if constexpr (std::is_floating_point_v<V>)
    s << detail::exact_number(value);
  else
    s << value;
  throw std::invalid_argument(s.str());
}

}  // namespace aolab
