#include "output_paths.h"

#include <fcntl.h>
#include <unistd.h>

#include <climits>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "dgtex/scene_io.h"

namespace fs = std::filesystem;

namespace dgtex::cli {
namespace {

// What `dgtex run` writes into its output folder besides the report.
constexpr const char* kRunOutputFiles[] = {"deformed.vtu", "cut_surface.obj", "final.state", "textures/enrichment.vdb"};
constexpr const char* kRunOutputFolders[] = {"frames", "textures"};

// access() answers from the permission bits, which root passes everywhere: /proc took root's
// --out and --json and failed only after the work. Creating (and removing) a file, and
// opening an existing one for writing (without truncating it), are the real tests.
bool can_create_files_in(const fs::path& folder) {
  std::string probe = (folder / ".dgtex-write-probe-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) return false;
  ::close(fd);
  ::unlink(probe.c_str());
  return true;
}

bool can_write(const fs::path& file) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);  // a FIFO without reader: refused
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

// The longest path the commands write below an output folder ("/frames/frame_NNNNN.png",
// "/textures/enrichment.vdb", with room to spare).
constexpr std::size_t kLongestWrittenName = 64;

// "" when every name in PATH fits the file systems' limit (NAME_MAX, 255 bytes) and the
// whole path, with what the commands write below it, the system's (PATH_MAX, 4096), else
// why not: such a path fails only when the command writes it, after its work.
std::string check_path_lengths(const fs::path& path) {
  for (const fs::path& part : path)
    if (part.native().size() > NAME_MAX)
      return "a name in '" + path.string() + "' has " + std::to_string(part.native().size()) +
             " bytes; file systems take at most " + std::to_string(NAME_MAX);
  if (path.native().size() + kLongestWrittenName >= PATH_MAX)
    return "the path has " + std::to_string(path.native().size()) +
           " bytes; with the names written in it the system takes at most " +
           std::to_string(PATH_MAX - 1 - kLongestWrittenName);
  return "";
}

// "" when FOLDER is a folder this process may create files in, else why not.
std::string check_writable_folder(const fs::path& folder) {
  std::error_code error;
  if (!fs::is_directory(folder, error)) return "'" + folder.string() + "' is not a folder";
  if (!can_create_files_in(folder)) return "folder '" + folder.string() + "' is not writable";
  return "";
}

}  // namespace

CLI::Validator writable_file() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        // Called only for a given option: an empty value is a mistake, not "no file".
        if (value.empty()) return "an empty path; give a file name";
        const fs::path path(value);
        if (std::string why = check_path_lengths(path); !why.empty()) return why;
        std::error_code error;
        if (fs::is_directory(path, error)) return "'" + value + "' is a folder; give a file name";
        // An existing file is written in place (write_output_file): its folder need not be
        // writable (/dev/null for a user).
        if (fs::exists(path, error)) return can_write(path) ? "" : "file '" + value + "' is not writable";
        const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
        if (!fs::exists(folder, error)) return "folder '" + folder.string() + "' does not exist";
        return check_writable_folder(folder);
      },
      "FILE");
}

CLI::Validator creatable_folder() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        // An empty --out would write into (and clear an earlier run's files from) the
        // working folder.
        if (value.empty()) return "an empty path; give a folder (\".\" for the working folder)";
        if (std::string why = check_path_lengths(fs::path(value)); !why.empty()) return why;
        fs::path existing = fs::absolute(fs::path(value)).lexically_normal();
        std::error_code error;
        while (!fs::exists(existing, error) && existing.has_relative_path()) existing = existing.parent_path();
        return check_writable_folder(existing);
      },
      "DIR");
}

namespace {

// A path as outputs are compared: absolute, symbolic links resolved where they exist.
fs::path comparable_path(const std::string& path) {
  std::error_code error;
  fs::path file = fs::weakly_canonical(fs::absolute(path), error);
  if (error) file = fs::absolute(path).lexically_normal();  // weakly_canonical gives an empty path then
  return file;
}

// Whether A and B name one file: the same path, or (both existing) the same inode, as
// through a hard link.
bool same_file(const fs::path& a, const fs::path& b) {
  if (comparable_path(a.string()) == comparable_path(b.string())) return true;
  std::error_code error;
  return fs::exists(a, error) && fs::exists(b, error) && fs::equivalent(a, b, error) && !error;
}

}  // namespace

bool outputs_are_distinct(const CLI::App& app,
                          std::initializer_list<std::pair<const char*, const std::string*>> outputs,
                          const std::vector<InputFile>& inputs) {
  std::vector<std::pair<const char*, fs::path>> given;
  for (const auto& [option, value] : outputs) {
    if (value->empty()) continue;
    const fs::path file = comparable_path(*value);
    for (const auto& [earlier, earlier_file] : given)
      if (earlier_file == file) {
        std::fprintf(stderr, "%s: %s and %s both name '%s'; give each its own file (the second would replace the first)\n",
                     app.get_name().c_str(), earlier, option, value->c_str());
        return false;
      }
    for (const InputFile& input : inputs)
      if (!input.path.empty() && same_file(input.path, *value)) {
        std::fprintf(stderr, "%s: %s '%s' is %s '%s'; give the output another file (it would replace the input)\n",
                     app.get_name().c_str(), option, value->c_str(), input.what.c_str(), input.path.c_str());
        return false;
      }
    given.emplace_back(option, file);
  }
  return true;
}

void create_output_folder(const std::string& folder, const char* option) {
  std::error_code error;
  fs::create_directories(folder, error);
  if (error)
    throw std::invalid_argument(std::string(option) + " " + folder + ": cannot create the folder (" + error.message() +
                                ")");
}

namespace {

// frame_ and at least five digits, then .vtu or .png: the names dgtex run gives its frames.
bool is_frame_file_name(const std::string& name) {
  const std::string prefix = "frame_";
  if (name.size() < prefix.size() + 5 + 4 || name.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string extension = name.substr(name.size() - 4);
  if (extension != ".vtu" && extension != ".png") return false;
  for (std::size_t i = prefix.size(); i < name.size() - 4; ++i)
    if (name[i] < '0' || name[i] > '9') return false;
  return true;
}

// The files of `dgtex run` in its output folder but its frames.
std::vector<std::string> run_output_names(const std::string& report_name) {
  std::vector<std::string> names = {report_name};
  // A run with its own output.report clears the default one too: another scene's report
  // must not stay beside it.
  const std::string default_report = OutputOptions{}.report;
  if (report_name != default_report) names.push_back(default_report);
  names.insert(names.end(), std::begin(kRunOutputFiles), std::end(kRunOutputFiles));
  return names;
}

bool remove_file(const fs::path& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return false;
  const bool removed = fs::remove(path, error);
  if (error)
    throw std::runtime_error("cannot remove '" + path.string() + "' of an earlier run (" + error.message() + ")");
  return removed;
}

}  // namespace

void check_report_name(const Scene& scene) {
  const std::string& name = scene.output.report;
  for (const char* taken : kRunOutputFiles)
    if (name == taken)
      throw SceneError(scene.source_name, "output.report", "the name of another output of dgtex run", "\"" + name + "\"",
                       "expected another file name, such as \"report.json\"");
  for (const char* taken : kRunOutputFolders)
    if (name == taken)
      throw SceneError(scene.source_name, "output.report", "the name of an output folder of dgtex run", "\"" + name + "\"",
                       "expected another file name, such as \"report.json\"");
}

int remove_earlier_run_outputs(const std::string& folder, const std::string& report_name) {
  const fs::path out(folder);
  int removed = remove_earlier_outputs(folder, run_output_names(report_name));
  std::vector<fs::path> frames;  // listed first: removing while iterating may skip entries
  std::error_code error;
  if (fs::is_directory(out / "frames", error))
    for (const fs::directory_entry& entry : fs::directory_iterator(out / "frames"))
      if (is_frame_file_name(entry.path().filename().string())) frames.push_back(entry.path());
  for (const fs::path& frame : frames) removed += remove_file(frame);
  return removed;
}

namespace {
[[noreturn]] void refuse_output_on_input(const std::string& folder, const InputFile& input) {
  throw std::invalid_argument("--out " + folder + ": the run writes or clears '" + input.path + "', " + input.what +
                              "; choose another output folder, or move the input out of it");
}
}  // namespace

void check_outputs_spare_inputs(const std::string& folder, const std::vector<std::string>& names,
                                const std::vector<InputFile>& inputs) {
  const fs::path out(folder);
  for (const InputFile& input : inputs) {
    if (input.path.empty()) continue;
    for (const std::string& name : names)
      if (same_file(input.path, out / name)) refuse_output_on_input(folder, input);
  }
}

int remove_earlier_outputs(const std::string& folder, const std::vector<std::string>& names) {
  int removed = 0;
  for (const std::string& name : names) removed += remove_file(fs::path(folder) / name);
  return removed;
}

void check_run_outputs_spare_inputs(const std::string& folder, const std::string& report_name,
                                    const std::vector<InputFile>& inputs) {
  check_outputs_spare_inputs(folder, run_output_names(report_name), inputs);
  for (const InputFile& input : inputs) {
    const fs::path path(input.path);
    if (!input.path.empty() && is_frame_file_name(path.filename().string()) &&
        same_file(path.parent_path(), fs::path(folder) / "frames"))
      refuse_output_on_input(folder, input);
  }
}

void write_output_file(const std::string& path, const std::string& text, const char* option) {
  std::ofstream out(path);
  out << text;
  out.close();  // a full disk (/dev/full) shows only when the buffer is written out
  if (!out) throw std::runtime_error(std::string("cannot write ") + option + " file '" + path + "'");
}

}  // namespace dgtex::cli
