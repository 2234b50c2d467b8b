#pragma once

namespace morph {
inline constexpr const char* kVersion = "0.1.0";
}  // namespace morph
