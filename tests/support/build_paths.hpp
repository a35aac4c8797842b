#pragma once
// Where this build's checkout, programs and test recordings are, for the tests. They are defined
// once, in a source CMake writes into the build folder (build_paths.cpp.in), not on each test's
// command line: a test's object is then the same in every checkout of the same sources, and a
// fresh clone's build (CI's) finds it in ccache. Included into every test and test helper by the
// compiler (surroundd_test_process, tests/support/CMakeLists.txt), so its namespace is one no
// test names (a surroundd::testing in every test would hide GoogleTest's ::testing in some).

namespace surroundd::test_paths {

const char* sourceDir();   // the checkout
const char* binaryDir();   // this build's folder
const char* fixtureDir();  // where the fixtures' recordings are made

}  // namespace surroundd::test_paths

// As the tests have always named them.
#define SURROUNDD_SOURCE_DIR (::surroundd::test_paths::sourceDir())
#define SURROUNDD_BINARY_DIR (::surroundd::test_paths::binaryDir())
#define SURROUNDD_FIXTURE_DIR (::surroundd::test_paths::fixtureDir())
