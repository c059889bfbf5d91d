// Reading a whole text file (text_file.hpp).
#include "text_file.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "nscd_sim/scene_loader.hpp"

namespace nscd {

std::string readTextFile(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw SceneError(path + ": cannot read file (a directory)");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw SceneError(path + ": cannot read file");
  std::stringstream buf;
  buf << f.rdbuf();
  if (f.bad()) throw SceneError(path + ": cannot read file");
  return buf.str();
}

}  // namespace nscd
