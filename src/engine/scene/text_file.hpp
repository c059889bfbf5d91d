// Reading a whole text file (a scene or a YAML config) with one-line errors.
#pragma once

#include <string>

namespace nscd {

// The file's text. Throws SceneError "PATH: cannot read file" (or "... (a directory)").
std::string readTextFile(const std::string& path);

}  // namespace nscd
