// The largest single heap allocation made while a function runs (the scene tests' global
// operator new, tests/scene/test_alloc_probe.cpp, records it): proves a hostile count is
// refused before anything big is allocated.
#pragma once

#include <cstddef>
#include <functional>

namespace vt::test {

size_t largest_allocation_during(const std::function<void()>& fn);

}  // namespace vt::test
