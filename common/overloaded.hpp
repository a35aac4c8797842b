#pragma once
// One callable of several lambdas, for std::visit over a variant: a case it lacks does not
// compile.

namespace surroundd {

template <class... Cases>
struct Overloaded : Cases... {
  using Cases::operator()...;
};
// GCC deduces it as an aggregate; clang before 17 needs the guide.
template <class... Cases>
Overloaded(Cases...) -> Overloaded<Cases...>;

}  // namespace surroundd
