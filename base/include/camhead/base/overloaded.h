// A visitor from lambdas, one per alternative of a variant:
//   std::visit(base::Overloaded{[](const A &a) {...}, [](const B &b) {...}}, v);
// An alternative without its lambda does not compile, which is the point:
// adding a kind of camera or sink makes every place that handles kinds say so.
#pragma once

namespace camhead::base {

template <typename... Handlers> struct Overloaded : Handlers... { using Handlers::operator()...; };

} // namespace camhead::base
