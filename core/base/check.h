// Internal invariant checks in the manner of pbrt-v4's util/check.h: a failed check reports
// both operands. They throw std::logic_error instead of aborting, because this library runs
// inside Blender, where an abort would end the artist's session.
// User input is validated at the API boundary with std::invalid_argument (see aolab.h);
// these checks are for conditions that only a bug in AO Lab can violate.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

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

/// Throws std::invalid_argument("<parameter> <requirement>, got <value>"): the one way user
/// input is rejected, so every message names the parameter and the offending value.
template <class V>
[[noreturn]] void throw_invalid(const std::string& parameter, const std::string& requirement,
                                const V& value) {
  std::ostringstream s;
  s << parameter << ' ' << requirement << ", got " << value;
  throw std::invalid_argument(s.str());
}

}  // namespace aolab
