// kincal: a controller backup compensated as a whole: every program file of the languages kincal reads in a
// folder (or in several files and folders) filtered, each in its own tools and bases and with every
// declaration of the backup in reach, the programs in parallel on all cores, and the same tree written under
// an output folder (every other file copied unchanged). A program that fails leaves no output of its own; the
// others are still written.
#pragma once

#include "kincal/compensation/controller_program.hpp"

#include <functional>
#include <string>
#include <vector>

namespace kincal {

/// What compensate_backup did with each program.
struct BackupProgram {
  std::vector<std::string> inputs;  ///< the files read as one program (a KRL .src with its .dat, modules that share targets, ...)
  ControllerProgramResult result;   ///< when written
  std::string error;                ///< "" when written; else the cause ("file:line: cause")
};

struct BackupResult {
  std::vector<BackupProgram> programs;  ///< in the order of their first input's path
  std::vector<std::string> copied;      ///< files copied unchanged (output paths)
  int failed = 0;                       ///< programs not written
};

/// How the files of a backup are found and where they go.
struct BackupOptions {
  std::vector<std::string> declarations;  ///< --declarations: more files whose declarations programs may name
  int threads = 0;                        ///< programs filtered at once; 0: every core
  /// called after each program with (programs done, programs in all); from the worker threads, one at a time
  std::function<void(size_t, size_t)> progress;
};

/// The program files under `inputs` (files, or folders read recursively; symbolic links not followed) filtered
/// into `out_dir` with the same tree (one folder: its contents; several inputs: each under its own name).
/// KRL .src (with its .dat), RAPID .mod/.modx/.sys, FANUC .ls and URScript .script files are programs; a KRL
/// .dat without its .src and a RAPID module without motions are declarations (written only when a program's
/// targets are declared in them). Declarations are read from every file of the language (RAPID: within the
/// task's folder) and from `declarations`. InputError for inputs that cannot be read or an out_dir inside them.
BackupResult compensate_backup(const Robot& robot, const std::vector<std::string>& inputs, const std::string& out_dir,
                               const ProgramOptions& opt, const WriterOptions& w, const NativeOptions& native,
                               const BackupOptions& b = {});

/// Whether a path is a folder (compensate's --program then takes a backup).
bool is_folder(const std::string& path);

}  // namespace kincal
