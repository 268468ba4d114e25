#include "runner.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "output.hpp"
#include "version.hpp"

namespace mpmtb::suite {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kMarker = "done.json";

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_stop_signal(int sig) {
  g_stop = sig;
}

// Installs SIGINT/SIGTERM handlers for the lifetime of a run_all call.
class StopSignals {
 public:
  StopSignals() {
    g_stop = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ {
  }, old_term_{};
};

std::optional<nlohmann::json> read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

std::string last_line(const fs::path& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

std::string number(double v) {
  return fmt::format("{:.17g}", v);
}

std::string clock_text(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
                   : fmt::format("{}:{:02}", s / 60, s % 60);
}

// Progress on stderr: one updating line on a terminal, a few plain lines
// otherwise, nothing when quiet.
class Progress {
 public:
  Progress(const RunnerOptions& o, int total, int before, bool timed = false)
      : quiet_(o.quiet),
        tty_(::isatty(STDERR_FILENO)),
        title_(o.title),
        total_(total),
        before_(before) {
    if (quiet_) return;
    fmt::print(stderr, "{}: {} runs: {} finished before, {} to run ({})\n", title_, total, before,
               total - before, timed ? "timed: one at a time" : fmt::format("{} at once", o.jobs));
  }
  void update(int ran, bool force = false) {
    if (quiet_) return;
    const auto now = Clock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    if (!force && since < (tty_ ? 0.2 : 15.0)) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const int todo = total_ - before_;
    const std::string eta =
        ran > 0 && ran < todo ? ", ~" + clock_text(elapsed / ran * (todo - ran)) + " left" : "";
    const std::string line = fmt::format("{}: {}/{} runs done, {} elapsed{}", title_, before_ + ran,
                                         total_, clock_text(elapsed), eta);
    if (tty_) {
      fmt::print(stderr, "\r{:<78}", line);
    } else {
      fmt::print(stderr, "{}\n", line);
    }
  }
  void finish(int ran) {
    if (quiet_) return;
    update(ran, true);
    if (tty_) fmt::print(stderr, "\n");
  }

 private:
  bool quiet_, tty_;
  std::string title_;
  int total_, before_;
  Clock::time_point start_ = Clock::now(), last_ = Clock::now() - std::chrono::hours(1);
};

struct Child {
  std::size_t index;
  Clock::time_point start;
  bool timed_out = false;
};

// Starts one child: `exe run ...` with stdout and stderr into DIR/log.txt. The
// child dies with the suite (PR_SET_PDEATHSIG), so a killed suite leaves no
// orphan writing into a folder that a resumed suite reuses.
pid_t launch(const std::string& exe, const RunSpec& spec, const fs::path& dir) {
  std::error_code ec;
  fs::remove_all(dir, ec);  // an unfinished attempt: start clean
  fs::create_directories(dir);
  std::vector<std::string> args = spec.arguments(dir);
  args.insert(args.begin(), exe);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string log = (dir / "log.txt").string();
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(fmt::format("fork failed: {}", std::strerror(errno)));
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(125);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      ::dup2(fd, STDOUT_FILENO);
      ::dup2(fd, STDERR_FILENO);
      ::close(fd);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

// After the child has exited: settle its summary, then write the marker.
RunResult settle(const RunSpec& spec, const fs::path& dir, int wait_status, bool timed_out,
                 double seconds) {
  RunResult r;
  auto summary = read_json(dir / "summary.json");
  const bool exited = WIFEXITED(wait_status);
  const int code = exited ? WEXITSTATUS(wait_status) : -1;
  nlohmann::json marker;
  marker["arguments"] = spec.arguments(dir);
  marker["revision"] = build_info().git_revision;
  marker["seconds"] = seconds;
  if (exited) {
    marker["exit_code"] = code;
  } else if (WIFSIGNALED(wait_status)) {
    marker["signal"] = WTERMSIG(wait_status);
  }
  if (!timed_out && exited && (code == 0 || code == 3 || code == 2) && summary &&
      summary->contains("status")) {
    r.status = summary->value("status", "");
    r.reason = summary->value("reason", "");
    r.summary = *summary;
  } else {
    if (timed_out) {
      r.status = "crashed";
      r.reason = "timed out";
    } else if (exited && code == 2) {
      r.status = "invalid";
      r.reason = last_line(dir / "log.txt");
    } else {
      r.status = "crashed";
      r.reason = exited ? fmt::format("exit status {}: {}", code, last_line(dir / "log.txt"))
                        : fmt::format("killed by signal {} ({})", WTERMSIG(wait_status),
                                      ::strsignal(WTERMSIG(wait_status)));
    }
    nlohmann::json j;
    j["status"] = r.status;
    j["reason"] = r.reason;
    j["scene"] = spec.scene;
    j["dim"] = spec.dim;
    j["transfer"] = spec.transfer;
    j["kernel"] = spec.kernel;
    j["integrator"] = spec.integrator.empty() ? "explicit" : spec.integrator;
    j["cells"] = spec.cells;
    j["ppc"] = spec.ppc;
    r.summary = j;
    write_atomically(dir / "summary.json", j.dump(2) + "\n");
  }
  marker["status"] = r.status;
  marker["reason"] = r.reason;
  write_atomically(dir / kMarker, marker.dump(2) + "\n");
  return r;
}

// What defines a run: its arguments less the value of --out. The folder is the
// run's identity already, and a suite folder on a shared filesystem may be
// mounted under another path on another host (or given relative there).
nlohmann::json definition(std::vector<std::string> args) {
  const auto out = std::find(args.begin(), args.end(), "--out");
  if (out != args.end() && out + 1 != args.end()) args.erase(out + 1);
  return args;
}

nlohmann::json recorded_definition(const nlohmann::json& recorded) {
  if (!recorded.is_array()) return recorded;
  std::vector<std::string> args;
  for (const auto& a : recorded) {
    if (!a.is_string()) return recorded;
    args.push_back(a.get<std::string>());
  }
  return definition(args);
}

// A finished run: its marker exists and records the same definition and git
// revision (a run left by an earlier suite definition or build is redone).
RunCheck check_marker(const RunSpec& spec, const fs::path& dir) {
  auto marker = read_json(dir / kMarker);
  if (!marker || !marker->contains("status")) return {std::nullopt, "no done.json"};
  const std::string revision = marker->value("revision", "");
  if (revision != build_info().git_revision) {
    return {std::nullopt, fmt::format("done.json of revision {}, this build is {}", revision,
                                      build_info().git_revision)};
  }
  if (recorded_definition(marker->value("arguments", nlohmann::json())) !=
      definition(spec.arguments(dir))) {
    return {std::nullopt, "done.json of other arguments (the suite's definition changed)"};
  }
  auto summary = read_json(dir / "summary.json");
  if (!summary) return {std::nullopt, "done.json but no readable summary.json"};
  return {RunResult{marker->value("status", ""), marker->value("reason", ""), *summary}, ""};
}

// A child stopped by SIGINT or SIGTERM (mpmtb run stops cleanly with 130 or
// 143): unfinished, not a result. Returns the signal, or 0.
int stop_signal_of(int wait_status) {
  if (WIFEXITED(wait_status)) {
    const int code = WEXITSTATUS(wait_status);
    return code == 128 + SIGINT ? SIGINT : code == 128 + SIGTERM ? SIGTERM : 0;
  }
  if (WIFSIGNALED(wait_status)) {
    const int sig = WTERMSIG(wait_status);
    return sig == SIGINT || sig == SIGTERM ? sig : 0;
  }
  return 0;
}

}  // namespace

std::vector<std::string> RunSpec::arguments(const fs::path& out) const {
  std::vector<std::string> a = {
      "run",      scene,  "--dim",   std::to_string(dim),   "--transfer", transfer,
      "--kernel", kernel, "--cells", std::to_string(cells), "--ppc",      std::to_string(ppc)};
  if (!integrator.empty()) a.insert(a.end(), {"--integrator", integrator});
  if (cfl) a.insert(a.end(), {"--cfl", number(*cfl)});
  if (dt) a.insert(a.end(), {"--dt", number(*dt)});
  if (t_end) a.insert(a.end(), {"--t-end", number(*t_end)});
  for (const auto& s : sets) a.insert(a.end(), {"--set", s});
  if (timing_repeats > 0) {
    a.insert(a.end(), {"--timing-repeats", std::to_string(timing_repeats), "--timing-min-seconds",
                       number(timing_min_seconds)});
  }
  a.insert(a.end(), {"--threads", "1", "--out", out.string()});
  return a;
}

std::vector<RunResult> run_all(const std::vector<RunSpec>& specs, const fs::path& root,
                               const RunnerOptions& options, RunnerStats* stats) {
  std::vector<RunResult> results(specs.size());
  std::deque<std::size_t> pending;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    if (auto r = check_marker(specs[i], root / specs[i].dir).result) {
      results[i] = std::move(*r);
    } else {
      pending.push_back(i);
    }
  }
  // The runs that may share the cores first, then the timed ones, one at a time.
  std::stable_partition(pending.begin(), pending.end(),
                        [&](std::size_t i) { return !specs[i].serial(); });
  const int total = static_cast<int>(specs.size());
  const int before = total - static_cast<int>(pending.size());
  if (stats) *stats = {total, before, 0};
  const bool timed =
      std::any_of(pending.begin(), pending.end(), [&](std::size_t i) { return specs[i].serial(); });
  Progress progress(options, total, before, timed);
  if (pending.empty()) return results;

  std::string exe = options.executable;
  if (exe.empty()) exe = fs::read_symlink("/proc/self/exe").string();
  const StopSignals stop_signals;
  std::map<pid_t, Child> running;
  int ran = 0;
  const int jobs = std::max(1, options.jobs);
  while (!pending.empty() || !running.empty()) {
    if (g_stop) {
      for (const auto& [pid, c] : running) ::kill(pid, SIGKILL);
      for (const auto& [pid, c] : running) ::waitpid(pid, nullptr, 0);
      progress.finish(ran);
      throw Interrupted(g_stop);
    }
    while (!pending.empty() && static_cast<int>(running.size()) < jobs) {
      const std::size_t i = pending.front();
      // A timed run starts alone, and nothing starts beside it.
      const bool alone = std::any_of(running.begin(), running.end(),
                                     [&](const auto& r) { return specs[r.second.index].serial(); });
      if (alone || (specs[i].serial() && !running.empty())) break;
      pending.pop_front();
      const pid_t pid = launch(exe, specs[i], root / specs[i].dir);
      running[pid] = {i, Clock::now()};
    }
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, WNOHANG);
    if (pid > 0 && running.count(pid)) {
      const Child c = running[pid];
      running.erase(pid);
      // A child that the same Ctrl-C stopped (mpmtb run stops cleanly on
      // SIGINT) is unfinished, not a result: the resumed suite runs it again.
      if (g_stop) continue;
      // A child stopped first: a batch system's time limit signals every
      // process of the job, and the suite stops with it.
      if (const int sig = stop_signal_of(status)) {
        g_stop = sig;
        continue;
      }
      const double seconds = std::chrono::duration<double>(Clock::now() - c.start).count();
      results[c.index] =
          settle(specs[c.index], root / specs[c.index].dir, status, c.timed_out, seconds);
      ++ran;
      if (stats) stats->ran = ran;
      progress.update(ran);
      continue;
    }
    for (auto& [p, c] : running) {
      if (!c.timed_out &&
          std::chrono::duration<double>(Clock::now() - c.start).count() > options.timeout_seconds) {
        c.timed_out = true;
        ::kill(p, SIGKILL);
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  progress.finish(ran);
  return results;
}

RunCheck check_run(const RunSpec& spec, const fs::path& root) {
  return check_marker(spec, root / spec.dir);
}

std::string failure_kind(const RunResult& r) {
  if (r.status == "ok") return "";
  if (r.status != "unstable") return r.status;
  const std::string& s = r.reason;
  if (s.find("non-finite") != std::string::npos) return "nan";
  if (s.find("J <= 0") != std::string::npos) return "J<=0";
  if (s.find("left the domain") != std::string::npos) return "left-domain";
  if (s.find("energy grew") != std::string::npos) return "energy-growth";
  return "other";
}

}  // namespace mpmtb::suite
