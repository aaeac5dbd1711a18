#include "output_paths.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace dgtex::cli {
namespace {

bool is_writable(const fs::path& path) { return ::access(path.c_str(), W_OK) == 0; }

// "" when FOLDER is a folder this process may create files in, else why not.
std::string check_writable_folder(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return "'" + folder.string() + "' is not a folder";
  if (!is_writable(folder)) return "folder '" + folder.string() + "' is not writable";
  return "";
}

}  // namespace

CLI::Validator writable_file() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        if (value.empty()) return "";
        const fs::path path(value);
        std::error_code error;
        if (fs::is_directory(path, error)) return "'" + value + "' is a folder; give a file name";
        const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
        if (!fs::exists(folder, error)) return "folder '" + folder.string() + "' does not exist";
        if (std::string why = check_writable_folder(folder); !why.empty()) return why;
        if (fs::exists(path, error) && !is_writable(path)) return "file '" + value + "' is not writable";
        return "";
      },
      "FILE");
}

CLI::Validator creatable_folder() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        if (value.empty()) return "";
        fs::path existing = fs::absolute(fs::path(value)).lexically_normal();
        std::error_code error;
        while (!fs::exists(existing, error) && existing.has_relative_path()) existing = existing.parent_path();
        return check_writable_folder(existing);
      },
      "DIR");
}

void create_output_folder(const std::string& folder, const char* option) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    throw std::invalid_argument(std::string(option) + " " + folder + ": cannot create the folder (" + error.message() +
                                ")");
}

void write_output_file(const std::string& path, const std::string& text, const char* option) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(std::string("cannot write ") + option + " file '" + path + "'");
}

}  // namespace dgtex::cli
