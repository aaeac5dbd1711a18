#pragma once
// The files and folders a command writes. Commands run for seconds to many minutes and
// write their results at the end, so a path they could not write is refused when the
// options are read, before the work, and the write itself names the option it came from.
#include <CLI/CLI.hpp>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "dgtex/scene.h"

namespace dgtex::cli {

// Accepts a path whose folder exists and may be written to, and which is not itself a
// folder or a read-only file. Refuses an empty path (CLI11 checks only options that were
// given) and names of more than 255 bytes.
CLI::Validator writable_file();

// Accepts an existing folder that may be written to, or a path whose nearest existing
// part is such a folder (the command creates the rest when it writes). Nothing is created
// here: a run that fails later leaves no empty output folder behind. Refuses an empty path
// and names of more than 255 bytes.
CLI::Validator creatable_folder();

// A file a command reads: what names it ("--scene", "the scene file") and its path.
struct InputFile {
  std::string what;
  std::string path;
};

// Whether the output files given to a command (options and their values; empty: not
// given) are distinct files and none of them is one of INPUTS; if not, prints one line
// naming the two options (or the option and the input) and the file to stderr, prefixed
// with the command's name (app's, "dgtex bench scaling"). One file given twice would keep
// only the output written last; an output on an input replaced the user's scene.
bool outputs_are_distinct(const CLI::App& app,
                          std::initializer_list<std::pair<const char*, const std::string*>> outputs,
                          const std::vector<InputFile>& inputs = {});

// Creates FOLDER and its parents (nothing when it exists); throws std::invalid_argument naming
// OPTION ("--out"), the folder and why it cannot be created.
void create_output_folder(const std::string& folder, const char* option);

// Throws SceneError naming output.report where the scene's report would take the name of
// another output of `dgtex run` (deformed.vtu, cut_surface.obj, final.state, the folders
// frames and textures): it would overwrite that output, or fail to be written at the end.
void check_report_name(const Scene& scene);

// Removes what an earlier `dgtex run` into FOLDER wrote, so that a run never leaves
// another run's files beside its own (a longer run's later frames, or the report of a run
// that finished where this one failed): frames/frame_NNNNN.vtu and .png, REPORT_NAME (and
// report.json, the default name), deformed.vtu, cut_surface.obj, final.state and
// textures/enrichment.vdb. Nothing else is touched. Returns how many files were removed;
// throws std::runtime_error naming a file that could not be.
int remove_earlier_run_outputs(const std::string& folder, const std::string& report_name);

// Throws std::invalid_argument naming --out FOLDER and the input where one of the files
// NAMES in FOLDER (what a command writes there, or clears of an earlier run) is one of
// INPUTS.
void check_outputs_spare_inputs(const std::string& folder, const std::vector<std::string>& names,
                                const std::vector<InputFile>& inputs);

// Removes those of the files NAMES in FOLDER that exist, an earlier run's; returns how many.
// Throws std::runtime_error naming a file that could not be removed.
int remove_earlier_outputs(const std::string& folder, const std::vector<std::string>& names);

// Throws std::invalid_argument naming --out FOLDER and the input where a file that
// `dgtex run` writes or removes in FOLDER (remove_earlier_run_outputs) is one of INPUTS (a
// scene saved as FOLDER/final.state was deleted by the run it started).
void check_run_outputs_spare_inputs(const std::string& folder, const std::string& report_name,
                                    const std::vector<InputFile>& inputs);

// Writes TEXT to PATH; throws std::runtime_error naming OPTION ("--json") and the path.
void write_output_file(const std::string& path, const std::string& text, const char* option);

}  // namespace dgtex::cli
