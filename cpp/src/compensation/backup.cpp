#include "kincal/compensation/backup.hpp"

#include "kincal/io/file.hpp"
#include "kincal/io/native.hpp"

#include "../core/thread_pool.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <set>

namespace kincal {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string ext_of(const fs::path& p) { return lower(p.extension().string()); }

// the language of a program file by its extension; Csv for a file kincal copies
ControllerFormat language_of(const fs::path& p) {
  const std::string e = ext_of(p);
  if (e == ".src" || e == ".dat") return ControllerFormat::Krl;
  if (e == ".mod" || e == ".modx" || e == ".sys") return ControllerFormat::Rapid;
  if (e == ".ls") return ControllerFormat::FanucLs;
  if (e == ".script") return ControllerFormat::UrScript;
  return ControllerFormat::Csv;
}

// a RAPID module's task: the folder it stands in, or the one above a PROGMOD / SYSMOD folder
std::string task_of(const fs::path& p) {
  fs::path dir = p.parent_path();
  const std::string name = lower(dir.filename().string());
  if (name == "progmod" || name == "sysmod") dir = dir.parent_path();
  return dir.string();
}

struct Input {
  std::string path;  // as found
  std::string rel;   // its path under out_dir
  std::string root;  // the input it was found in (a file's: its folder)
};

// where a program's declarations are looked up: KRL the controller (the folder holding System/$config.dat
// above the file, else the input it came in); RAPID its task
std::string scope_of(const Input& f) {
  if (language_of(f.path) == ControllerFormat::Rapid) return "rapid:" + task_of(f.path);
  const fs::path root = fs::path(f.root).lexically_normal();
  for (fs::path dir = fs::path(f.path).parent_path(); !dir.empty(); dir = dir.parent_path()) {
    std::error_code ec;
    for (const char* name : {"$config.dat", "$CONFIG.DAT", "$Config.dat"})
      if (fs::exists(dir / "System" / name, ec)) return "krl:" + dir.string();
    if (dir.lexically_normal() == root || dir == dir.parent_path()) break;
  }
  return "krl:" + f.root;
}

// every file under the inputs, with its place in the output tree
std::vector<Input> files_of(const std::vector<std::string>& inputs, const std::string& out_dir) {
  std::vector<Input> out;
  const fs::path out_abs = fs::weakly_canonical(fs::path(out_dir));
  for (const std::string& in : inputs) {
    std::error_code ec;
    const fs::file_status st = fs::status(in, ec);
    if (ec || !fs::exists(st)) throw InputError(in + ": no such file or folder");
    if (!fs::is_directory(st)) {
      if (fs::weakly_canonical(fs::path(out_dir) / fs::path(in).filename()) == fs::weakly_canonical(fs::path(in)))
        throw InputError("--out " + out_dir + ": would write over the input " + in + " (give another folder)");
      const std::string parent = fs::path(in).parent_path().string();
      out.push_back({in, fs::path(in).filename().string(), parent.empty() ? "." : parent});
      if (ext_of(in) == ".src")  // a KRL program given as a file comes with its data list
        for (const char* e : {".dat", ".DAT", ".Dat"}) {
          fs::path dat = in;
          dat.replace_extension(e);
          if (fs::exists(dat, ec) && std::find(inputs.begin(), inputs.end(), dat.string()) == inputs.end()) {
            out.push_back({dat.string(), dat.filename().string(), parent.empty() ? "." : parent});
            break;
          }
        }
      continue;
    }
    const fs::path root = fs::weakly_canonical(fs::path(in));
    const std::string out_rel = fs::relative(out_abs, root).string();
    if (!out_rel.empty() && out_rel.rfind("..", 0) != 0)
      throw InputError("--out " + out_dir + ": inside the input folder " + in + " (give a folder beside it)");
    const std::string prefix = inputs.size() == 1 ? "" : fs::path(in).lexically_normal().filename().string();
    std::vector<Input> found;
    for (auto it = fs::recursive_directory_iterator(in, fs::directory_options::none, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (!it->is_regular_file()) continue;
      const fs::path rel = fs::relative(it->path(), in);
      found.push_back({it->path().string(), (prefix.empty() ? rel : fs::path(prefix) / rel).string(), in});
    }
    if (ec) throw InputError(in + ": " + ec.message());
    std::sort(found.begin(), found.end(), [](const Input& a, const Input& b) { return a.rel < b.rel; });
    out.insert(out.end(), found.begin(), found.end());
  }
  std::set<std::string> rels;
  for (const Input& f : out)
    if (!rels.insert(f.rel).second) throw InputError(f.path + ": two inputs give the output file " + f.rel);
  return out;
}

struct UnionFind {
  std::vector<size_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), size_t{0}); }
  size_t find(size_t i) { return parent[i] == i ? i : parent[i] = find(parent[i]); }
  void join(size_t a, size_t b) { parent[find(a)] = find(b); }
};

// runs f(i) for i in [0, n) on `threads` threads of the process's pool (0: every core; no more than
// the cores); the first exception f lets out (a progress callback interrupted) stops the handing out
// of indices and is rethrown once every running index is done
void parallel_for(size_t n, int threads, const std::function<void(size_t)>& f) {
  detail::parallel_pieces(n, 1, threads > 0 ? static_cast<size_t>(threads) : 0, [&](size_t begin, size_t end, size_t) {
    for (size_t i = begin; i < end; ++i) f(i);
  });
}

struct ReadProgram {  // a program file read alone, or why it cannot be
  NativeProgram p;
  std::string error;
};

struct BackupContexts {  // the declarations each program reads its targets from
  std::map<std::string, std::string> scope;                                 // program file -> its scope
  std::map<std::string, std::shared_ptr<const Declarations>> declarations;  // scope -> its declarations
  std::shared_ptr<const Declarations> of(const std::string& path) const {
    const auto s = scope.find(path);
    const auto it = s == scope.end() ? declarations.end() : declarations.find(s->second);
    return it == declarations.end() ? nullptr : it->second;
  }
};

// the declarations: KRL per controller (every data list under it), RAPID per task; plus --declarations
BackupContexts backup_declarations(const std::vector<Input>& files, const BackupOptions& b) {
  BackupContexts out;
  auto& scope = out.scope;
  auto& contexts = out.declarations;
  std::map<std::string, std::vector<std::string>> decl_files;  // scope -> files
  for (const Input& f : files) {
    const ControllerFormat l = language_of(f.path);
    if (l != ControllerFormat::Krl && l != ControllerFormat::Rapid) continue;
    scope[f.path] = scope_of(f);
    auto& list = decl_files[scope[f.path]];  // (a scope with programs only still takes --declarations)
    if (l == ControllerFormat::Rapid || ext_of(f.path) == ".dat") list.push_back(f.path);
  }
  std::vector<std::string> extra_krl, extra_rapid;
  for (const std::string& d : b.declarations) {
    const ControllerFormat l = language_of(d);
    if (l == ControllerFormat::Krl) extra_krl.push_back(d);
    else if (l == ControllerFormat::Rapid) extra_rapid.push_back(d);
    else throw InputError("--declarations " + d + ": a KRL .dat or a RAPID module (.mod, .modx, .sys)");
  }
  for (auto& [key, list] : decl_files) {
    const bool krl = key.rfind("krl:", 0) == 0;
    std::vector<std::string> all = krl ? extra_krl : extra_rapid;  // --declarations first: they win
    all.insert(all.end(), list.begin(), list.end());
    contexts[key] = std::make_shared<const Declarations>(
        read_declarations(all, krl ? ControllerFormat::Krl : ControllerFormat::Rapid));
  }
  return out;
}

// programs that write the same file (targets declared in a shared module) are read and written as one:
// the groups of programs (indices), in the order of their first program
std::vector<std::vector<size_t>> joined_programs(const std::vector<std::string>& programs,
                                                 const std::vector<ReadProgram>& alone) {
  std::map<std::string, size_t> owner;
  UnionFind uf(programs.size());
  for (size_t i = 0; i < programs.size(); ++i)
    for (const std::string& f : alone[i].p.paths) {
      const auto [it, fresh] = owner.emplace(f, i);
      if (!fresh) uf.join(i, it->second);
    }
  std::map<size_t, std::vector<size_t>> groups;
  for (size_t i = 0; i < programs.size(); ++i) groups[uf.find(i)].push_back(i);
  std::vector<std::vector<size_t>> jobs;
  for (auto& [root, members] : groups) jobs.push_back(members);
  std::sort(jobs.begin(), jobs.end(), [&](const auto& x, const auto& y) { return programs[x[0]] < programs[y[0]]; });
  return jobs;
}

// a written program owns every file it wrote; a failed one its own files (its programs, a KRL program's .dat),
// which get no output (an earlier run's is removed); every other file is copied unchanged: files no written
// program wrote (data lists and modules a failed program shares), programs with nothing to compensate
void settle_backup_files(BackupResult& r, const std::vector<Input>& files,
                         const std::map<std::string, std::string>& rel_of, const std::set<std::string>& paths,
                         const std::vector<char>& copy_unchanged,
                         const std::vector<std::vector<std::string>>& job_files) {
  std::set<std::string> owned;
  for (size_t j = 0; j < copy_unchanged.size(); ++j) {
    if (copy_unchanged[j]) continue;
    if (r.programs[j].error.empty()) {
      owned.insert(job_files[j].begin(), job_files[j].end());
      continue;
    }
    ++r.failed;
    std::vector<std::string> own = r.programs[j].inputs;
    for (const std::string& in : r.programs[j].inputs)
      if (language_of(in) == ControllerFormat::Krl)
        for (const char* e : {".dat", ".DAT", ".Dat"}) {
          fs::path dat = in;
          dat.replace_extension(e);
          if (paths.count(dat.string())) own.push_back(dat.string());
        }
    for (const std::string& f : own) {
      owned.insert(f);
      std::error_code ec;
      if (rel_of.count(f)) fs::remove(rel_of.at(f), ec);
    }
  }
  for (const Input& f : files) {
    if (owned.count(f.path)) continue;
    const std::string to = rel_of.at(f.path);
    std::error_code ec;
    fs::create_directories(fs::path(to).parent_path(), ec);
    if (!ec) fs::copy_file(f.path, to, fs::copy_options::overwrite_existing, ec);
    if (ec) {  // listed with the programs, as a failure of its own
      BackupProgram failed;
      failed.inputs = {f.path};
      failed.error = to + ": cannot copy " + f.path + " (" + ec.message() + ")";
      r.programs.push_back(failed);
      ++r.failed;
      continue;
    }
    r.copied.push_back(to);
  }
}

}  // namespace

bool is_folder(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

BackupResult compensate_backup(const Robot& robot, const std::vector<std::string>& inputs, const std::string& out_dir,
                               const ProgramOptions& opt, const WriterOptions& w, const NativeOptions& native,
                               const BackupOptions& b) {
  if (inputs.empty()) throw InputError("--program: no input");
  const std::vector<Input> files = files_of(inputs, out_dir);
  std::map<std::string, std::string> rel_of;  // input path -> output path under out_dir
  std::set<std::string> paths;
  for (const Input& f : files) rel_of[f.path] = (fs::path(out_dir) / f.rel).string(), paths.insert(f.path);
  const BackupContexts ctx = backup_declarations(files, b);
  // the programs: each program file alone first
  std::vector<std::string> programs;
  for (const Input& f : files) {
    const ControllerFormat l = language_of(f.path);
    if (l == ControllerFormat::Csv) continue;
    if (l == ControllerFormat::Krl && ext_of(f.path) == ".dat") continue;  // read with its .src, or a data list
    programs.push_back(f.path);
  }
  std::vector<ReadProgram> alone(programs.size());
  const auto read = [&](const std::vector<std::string>& ps) {
    const auto decl = ctx.of(ps[0]);
    return read_native_programs(ps, language_of(ps[0]), decl ? *decl : Declarations());
  };
  parallel_for(programs.size(), b.threads, [&](size_t i) {
    try {
      alone[i].p = read({programs[i]});
    } catch (const std::exception& e) {
      alone[i].error = e.what();
    }
  });
  BackupResult r;
  const std::vector<std::vector<size_t>> jobs = joined_programs(programs, alone);
  r.programs.resize(jobs.size());
  std::vector<char> copy_unchanged(jobs.size(), 0);
  std::vector<std::vector<std::string>> job_files(jobs.size());  // per job: the files it read (and writes)
  std::mutex progress_mutex;
  size_t done = 0;
  parallel_for(jobs.size(), b.threads, [&](size_t j) {
    BackupProgram& out = r.programs[j];
    for (const size_t i : jobs[j]) out.inputs.push_back(programs[i]);
    try {
      for (const size_t i : jobs[j])
        if (!alone[i].error.empty()) throw InputError(alone[i].error);
      const NativeProgram p = jobs[j].size() == 1 ? std::move(alone[jobs[j][0]].p) : read(out.inputs);
      job_files[j] = p.paths;
      if (p.targets.empty() && (p.unresolved.empty() || native.skip_unresolved)) {
        copy_unchanged[j] = 1;  // joints only, or nothing to move: the file as it is
        for (const auto& u : p.unresolved)
          out.result.result.warnings.push_back(u.where + ": " + u.why + ", passed through unchanged: " + u.text);
      } else {
        for (const std::string& f : p.paths)
          if (!rel_of.count(f))
            throw InputError(f + ": targets of " + out.inputs[0] + " are declared here, outside the backup: kincal "
                             "writes only the backup's files");
        for (const std::string& f : p.paths) fs::create_directories(fs::path(rel_of.at(f)).parent_path());
        WriterOptions wj = w;
        wj.format = p.format;
        out.result = compensate_native_program(robot, p, [&](const std::string& f) { return rel_of.at(f); }, opt, wj, native);
      }
    } catch (const std::exception& e) {
      out.error = e.what();
    }
    if (b.progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      b.progress(++done, jobs.size());
    }
  });
  settle_backup_files(r, files, rel_of, paths, copy_unchanged, job_files);
  return r;
}

}  // namespace kincal
