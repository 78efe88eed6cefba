// The headers nearly every test file includes, parsed once per test binary
// of eight files or more (CMake's precompiled header, tests/CMakeLists.txt)
// instead of once per file. Compiling test_renderer and test_pipeline went
// from 379 to 324 s of CPU (bench/RESULTS.md, "CI's time, third pass").
// Each test file still includes what it uses; a build with
// -DCAMHEAD_PRECOMPILED_HEADERS=OFF compiles every file on its own includes.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/glm.hpp>

#include <gtest/gtest.h>
