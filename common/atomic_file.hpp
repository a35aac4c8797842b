#pragma once
// A file replaced whole or not at all: written beside it as FILE.part, looked at, then renamed
// over it. A reader never sees half of it; a write that fails (a full disk) or a check that
// refuses it leaves the old file as it was and no part behind.
//
// Errors: std::runtime_error naming the file; what `check` throws, as it threw it.

#include <filesystem>
#include <functional>
#include <string_view>

namespace surroundd {

// `check`, when given, reads the written part (its path) before it takes the name.
void writeFileAtomically(const std::filesystem::path& file, std::string_view bytes,
                         const std::function<void(const std::filesystem::path&)>& check = {});

}  // namespace surroundd
