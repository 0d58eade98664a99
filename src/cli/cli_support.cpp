#include "cli_support.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <semaphore.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

#include "globemesh/error.hpp"
#include "globemesh/output_file.hpp"

namespace globemesh::cli {

namespace {

volatile std::sig_atomic_t g_interrupted = 0; // the first cancelling signal that arrived, or 0
volatile std::sig_atomic_t g_mid_line = 0;    // a progress line on stderr is open
volatile std::sig_atomic_t g_completing = 0;  // the outputs are being moved in place: no cancel
pthread_t g_main_thread;                      // the thread of the guard, which handles the signals
sem_t g_wake;                                 // posted by the first signal and by the guard's end
std::atomic<bool> g_guard_ending{false};

void write_stderr(const char *text) {
    for (std::size_t left = std::strlen(text); left > 0;) {
        const ssize_t n = ::write(STDERR_FILENO, text, left);
        if (n <= 0)
            return;
        text += n, left -= static_cast<std::size_t>(n);
    }
}

/// The first signal asks the run to stop at its next progress report, which then unwinds and
/// removes its files. A second one ends the process at once (Ctrl-C twice, or a run stuck in a
/// call that does not report), after removing the temporary files itself; unless the outputs
/// are being moved in place, which takes a few system calls and leaves them all complete.
/// Handled on the guard's thread, so that no other thread of the run writes meanwhile.
extern "C" void on_cancelling_signal(int signal) {
    if (!pthread_equal(pthread_self(), g_main_thread)) {
        pthread_kill(g_main_thread, signal);
        return;
    }
    if (g_completing)
        return; // the run ends with its outputs (InterruptGuard::completing)
    if (!g_interrupted) {
        g_interrupted = signal;
        sem_post(&g_wake); // the watchdog's clock starts
        return;
    }
    if (OutputFile::committing())
        return;
    OutputFile::remove_temporaries();
    if (g_mid_line)
        write_stderr("\n");
    write_stderr(signal == SIGTERM  ? "globemesh: cancelled by SIGTERM, no output written\n"
                 : signal == SIGHUP ? "globemesh: cancelled by SIGHUP, no output written\n"
                                    : "globemesh: cancelled, no output written\n");
    std::signal(signal, SIG_DFL);
    std::raise(signal);
}

/// Waits for a first signal; when the run has not ended stop_grace after it (a long call that
/// does not report: a GEOS validity test of a continent, a library's write), sends the signal
/// again, which ends the process as a second one does.
void watchdog() {
    while (sem_wait(&g_wake) != 0 && errno == EINTR) {
    }
    if (g_guard_ending.load())
        return;
    timespec deadline{};
    clock_gettime(CLOCK_REALTIME, &deadline);
    const long grace_ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(InterruptGuard::stop_grace).count();
    deadline.tv_sec += (deadline.tv_nsec + grace_ns) / 1000000000L;
    deadline.tv_nsec = (deadline.tv_nsec + grace_ns) % 1000000000L;
    int waited = 0;
    while ((waited = sem_timedwait(&g_wake, &deadline)) != 0 && errno == EINTR) {
    }
    if (waited != 0 && !g_guard_ending.load())
        pthread_kill(g_main_thread, g_interrupted);
}

} // namespace

InterruptGuard::InterruptGuard() {
    g_interrupted = 0;
    g_completing = 0;
    g_main_thread = pthread_self();
    g_guard_ending = false;
    sem_init(&g_wake, 0, 0);
    watchdog_ = std::thread(watchdog);
    struct sigaction action {};
    action.sa_handler = on_cancelling_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    for (std::size_t k = 0; k < std::size(cancelling); ++k)
        installed_[k] = sigaction(cancelling[k], &action, &previous_[k]) == 0;
}

InterruptGuard::~InterruptGuard() {
    g_guard_ending = true;
    sem_post(&g_wake);
    watchdog_.join();
    // A run that completed ignores the signals until the process ends: one arriving between
    // here and exit would otherwise end it by the default action, its outputs all in place.
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    for (std::size_t k = 0; k < std::size(cancelling); ++k)
        if (installed_[k])
            sigaction(cancelling[k], g_completing ? &ignore : &previous_[k], nullptr);
    sem_destroy(&g_wake);
}

bool InterruptGuard::interrupted() {
    return g_interrupted != 0;
}

int InterruptGuard::signal() {
    return g_interrupted;
}

void InterruptGuard::forget() {
    g_interrupted = 0;
}

void InterruptGuard::completing() {
    g_completing = 1;
}

bool TerminalProgress::update(double fraction, std::string_view stage) {
    if (InterruptGuard::interrupted())
        return false;
    if (quiet_)
        return true;
    if (verbose_ && stage != stage_) {
        if (mid_line_)
            err_ << '\n';
        err_ << '[' << stage << "] ";
        stage_ = std::string(stage);
        mid_line_ = true;
        g_mid_line = 1;
    }
    // GDALTermProgress's arithmetic: 40 ticks, a number every fourth, " - done." at 100.
    const int tick = std::clamp(static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 40.0), 0, 40);
    if (tick < last_tick_ && last_tick_ >= 39)
        last_tick_ = -1; // a new run of 0..100
    // Without --verbose the line starts at the first tick after 0, so that an error found while
    // the inputs are opened stands alone, without a "0" before it.
    if (tick <= last_tick_ || (tick == 0 && !verbose_))
        return true;
    while (tick > last_tick_) {
        ++last_tick_;
        if (last_tick_ % 4 == 0)
            err_ << (last_tick_ / 4) * 10;
        else
            err_ << '.';
    }
    mid_line_ = true;
    if (tick == 40) {
        err_ << " - done.\n";
        mid_line_ = false;
    }
    err_.flush();
    g_mid_line = mid_line_;
    return true;
}

void TerminalProgress::end_line() {
    if (mid_line_)
        err_ << '\n';
    mid_line_ = false;
    g_mid_line = 0;
}

std::string json_number(double v) {
    if (!std::isfinite(v))
        return "null";
    char buffer[32];
    auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return std::string(buffer, end);
}

std::string json_string(const std::string &s) {
    std::string r = "\"";
    for (unsigned char c : s) {
        switch (c) {
        case '"':
            r += "\\\"";
            break;
        case '\\':
            r += "\\\\";
            break;
        case '\n':
            r += "\\n";
            break;
        case '\t':
            r += "\\t";
            break;
        case '\r':
            r += "\\r";
            break;
        default:
            if (c < 0x20) {
                char esc[8];
                std::snprintf(esc, sizeof esc, "\\u%04x", c);
                r += esc;
            } else {
                r += static_cast<char>(c);
            }
        }
    }
    return r + "\"";
}

std::string stages_json(const StageTimings &timings) {
    std::string s = "{";
    for (std::size_t i = 0; i < timings.stages.size(); ++i) {
        s += (i ? ", " : "") + json_string(timings.stages[i].first) + ": " +
             json_number(timings.stages[i].second);
    }
    return s + "}";
}

std::string stats_json(const MeshStats &st, const std::string &in) {
    std::ostringstream o;
    const std::string in2 = in + "  ";
    o << "{\n"
      << in2 << "\"nodes\": " << st.nodes << ",\n"
      << in2 << "\"faces\": " << st.faces << ",\n"
      << in2 << "\"edges\": " << st.edges << ",\n"
      << in2 << "\"boundary_edges\": " << st.boundary_edges << ",\n"
      << in2 << "\"boundary_loops\": " << st.boundary_loops << ",\n"
      << in2 << "\"extent_deg\": {\"lon_min\": " << json_number(st.lon_min)
      << ", \"lon_max\": " << json_number(st.lon_max)
      << ", \"lat_min\": " << json_number(st.lat_min)
      << ", \"lat_max\": " << json_number(st.lat_max) << "},\n"
      << in2 << "\"area_km2\": " << json_number(st.area_km2) << ",\n"
      << in2 << "\"edge_km\": {\"min\": " << json_number(st.edge_km_min)
      << ", \"mean\": " << json_number(st.edge_km_mean)
      << ", \"max\": " << json_number(st.edge_km_max) << "},\n"
      << in2 << "\"quality\": {\"min\": " << json_number(st.quality_min)
      << ", \"mean\": " << json_number(st.quality_mean)
      << ", \"above_0_8\": " << json_number(st.quality_above_0_8) << ",\n"
      << in2 << "  \"histogram_edges\": [0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1],\n"
      << in2 << "  \"histogram\": [";
    for (std::size_t i = 0; i < st.quality_histogram.size(); ++i)
        o << (i ? ", " : "") << st.quality_histogram[i];
    o << "]}";
    if (st.has_size) {
        o << ",\n"
          << in2 << "\"size_ratio\": {\"median\": " << json_number(st.size_ratio_median)
          << ", \"in_0_7_1_4\": " << json_number(st.size_ratio_in_range) << "}";
    }
    o << "\n" << in << "}";
    return o.str();
}

void print_stats(std::ostream &out, const MeshStats &st, bool histogram) {
    auto old_flags = out.flags();
    auto old_precision = out.precision();
    out << std::fixed;
    out << "nodes             " << st.nodes << "\n"
        << "faces             " << st.faces << "\n"
        << "edges             " << st.edges << "\n"
        << "boundary          " << st.boundary_edges << " edges in " << st.boundary_loops
        << " loops\n"
        << std::setprecision(4) << "extent            lon " << st.lon_min << " .. " << st.lon_max
        << ", lat " << st.lat_min << " .. " << st.lat_max << " (degrees)\n"
        << std::setprecision(1) << "area              " << st.area_km2 << " km2\n"
        << std::setprecision(3) << "edge length       min " << st.edge_km_min << "  mean "
        << st.edge_km_mean << "  max " << st.edge_km_max << " (km)\n"
        << "quality           min " << st.quality_min << "  mean " << st.quality_mean
        << "  above 0.8 " << std::setprecision(1) << 100 * st.quality_above_0_8 << "%\n";
    if (st.has_size) {
        out << std::setprecision(3) << "edge / target     median " << st.size_ratio_median
            << "  in [0.7, 1.4] " << std::setprecision(1) << 100 * st.size_ratio_in_range << "%\n";
    }
    if (histogram) {
        out << "quality histogram\n";
        std::size_t total = 0, largest = 0;
        for (auto c : st.quality_histogram)
            total += c, largest = std::max(largest, c);
        for (std::size_t i = 0; i < st.quality_histogram.size(); ++i) {
            const std::size_t c = st.quality_histogram[i];
            const int bar = largest ? static_cast<int>(std::lround(40.0 * c / largest)) : 0;
            out << "  [" << std::setprecision(1) << 0.1 * i << ", " << 0.1 * (i + 1)
                << (i == 9 ? ']' : ')');
            out << ' ' << std::setw(10) << c << ' ' << std::setw(5) << std::setprecision(1)
                << (total ? 100.0 * c / total : 0.0) << '%';
            // (The bar is written on its own: " " + std::string(bar, '#') trips GCC 12's
            // known -Wrestrict false positive.)
            if (bar)
                out << ' ' << std::string(bar, '#');
            out << '\n';
        }
    }
    out.flags(old_flags);
    out.precision(old_precision);
}

void print_timings(std::ostream &out, const StageTimings &timings) {
    auto old_flags = out.flags();
    auto old_precision = out.precision();
    out << "time (s)";
    bool first = true;
    for (const auto &[name, seconds] : timings.stages) {
        out << (first ? "          " : "                  ") << name << ' ' << std::fixed
            << std::setprecision(3) << seconds << "\n";
        first = false;
    }
    if (first)
        out << "\n";
    out.flags(old_flags);
    out.precision(old_precision);
}

long long peak_memory_bytes() {
    struct rusage usage {};
    if (getrusage(RUSAGE_SELF, &usage) != 0)
        return 0;
    return static_cast<long long>(usage.ru_maxrss) * 1024; // Linux reports kilobytes
}

std::uint64_t default_memory_budget_bytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0)
        return 0;
    return static_cast<std::uint64_t>(pages) / 4 * 3 * static_cast<std::uint64_t>(page_size);
}

namespace {

/// True for names GDAL resolves itself: /vsi... paths and "SCHEME:..." connection strings.
bool is_gdal_special(const std::string &path) {
    if (path.rfind("/vsi", 0) == 0)
        return true;
    const auto colon = path.find(':');
    if (colon == std::string::npos || colon < 2)
        return false; // "C:" style or none
    for (std::size_t i = 0; i < colon; ++i)
        if (!std::isalpha(static_cast<unsigned char>(path[i])))
            return false;
    return true;
}

/// The error text of creating a file in `folder`, or "" when it can: a probe file made and
/// removed at once, as a folder can look writable (root on /proc) and take no file.
std::string cannot_create_in(const std::filesystem::path &folder) {
    const std::filesystem::path probe = folder / (".globemesh-probe-" + std::to_string(::getpid()));
    const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0)
        return errno == EEXIST ? "" : std::strerror(errno);
    ::close(fd);
    ::unlink(probe.c_str());
    return "";
}

} // namespace

void check_output_path(const std::string &path, const std::string &what, bool overwrite) {
    namespace fs = std::filesystem;
    fs::path p(path);
    fs::path folder = p.parent_path();
    if (folder.empty())
        folder = ".";
    std::error_code ec;
    if (!fs::is_directory(folder, ec))
        throw IoError(what + ": the folder " + folder.string() + " of " + path +
                      " does not exist; create it first");
    // JSON goes to a terminal or pipe as it is (--report /dev/stdout); nothing else can.
    if (OutputFile::is_stream(p)) {
        if (what == "--report" || what == "--timings")
            return;
        throw IoError(what + ": " + path +
                      " is not a regular file (a device or pipe); give a file name");
    }
    if (fs::is_directory(p, ec)) // before "exists": --overwrite would not help
        throw IoError(what + ": " + path + " is a folder; give a file name");
    if (fs::exists(p, ec) && !overwrite)
        throw IoError(what + ": " + path + " exists; use --overwrite to replace it");
    if (fs::exists(p, ec) && !fs::is_regular_file(p, ec))
        throw IoError(what + ": " + path + " is not a regular file (a socket?); give a file name");
    if (const std::string reason = cannot_create_in(folder); !reason.empty())
        throw IoError(what + ": " + path + ": the folder " + folder.string() +
                      " takes no new file (" + reason + ")");
}

void check_input_path(const std::string &path, const std::string &what) {
    if (path.empty() || is_gdal_special(path))
        return;
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw IoError(what + ": " + path + " does not exist");
}

void check_not_an_input(const std::string &path, const std::string &what,
                        std::span<const std::pair<std::string, std::string>> inputs) {
    std::error_code ec;
    for (const auto &[option, input] : inputs)
        if (!input.empty() && std::filesystem::equivalent(path, input, ec) && !ec)
            throw UsageError(
                what + " " + path + " is the " + option +
                " file: the run would replace what it reads; write the output elsewhere");
}

} // namespace globemesh::cli
