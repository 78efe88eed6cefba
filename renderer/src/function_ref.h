// A callable passed down a call and not kept: a pointer to it and a
// function that calls it, where std::function would copy a lambda with more
// than two pointers' worth of captures to the heap on every call (the live
// frame allocates nothing: frame_allocations_test.cpp). The callable must
// outlive the FunctionRef, as a temporary does a call it is passed to.
#pragma once

#include <functional>
#include <memory>
#include <type_traits>
#include <utility>

namespace camhead::renderer {

template <typename Signature> class FunctionRef;

template <typename Result, typename... Args> class FunctionRef<Result(Args...)> {
public:
  // None: operator bool() is false, and calling it is not allowed.
  FunctionRef() = default;

  template <typename Callable>
  requires(!std::is_same_v<std::remove_cvref_t<Callable>, FunctionRef> &&
           std::is_invocable_r_v<Result, Callable &, Args...>)
      FunctionRef(Callable &&callable) // NOLINT: converts as std::function does
      : object_(const_cast<void *>(static_cast<const void *>(std::addressof(callable)))),
        call_([](void *object, Args... args) -> Result {
          return std::invoke(*static_cast<std::remove_reference_t<Callable> *>(object),
                             std::forward<Args>(args)...);
        }) {}

  Result operator()(Args... args) const { return call_(object_, std::forward<Args>(args)...); }
  explicit operator bool() const { return call_ != nullptr; }

private:
  void *object_ = nullptr;
  Result (*call_)(void *, Args...) = nullptr;
};

} // namespace camhead::renderer
