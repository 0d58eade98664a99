// GEOS's interrupt tied to a Progress: see geos_interrupt.hpp.
#include "geos_interrupt.hpp"

#include <geos_c.h>

#include <chrono>
#include <string>

namespace globemesh::coast {

struct GeosInterrupt::State {
    Progress parent;
    double fraction = 0;
    std::string stage;
    std::chrono::steady_clock::time_point last_check = std::chrono::steady_clock::now();
    unsigned calls = 0;
    bool stopped = false;
    State *outer = nullptr;
    GEOSInterruptCallback *previous = nullptr;
};

namespace {

using Clock = std::chrono::steady_clock;
constexpr auto check_interval = std::chrono::milliseconds(50);
/// GEOS calls the callback in its inner loops: the clock is read every this many calls only.
constexpr unsigned calls_per_clock = 64;

thread_local GeosInterrupt::State *active = nullptr;

/// Repeats the last report to the run's progress when check_interval has passed; true once the
/// run asked to stop.
bool stop_requested(GeosInterrupt::State &s) {
    if (s.stopped)
        return true;
    const auto now = Clock::now();
    if (now - s.last_check < check_interval)
        return false;
    s.last_check = now;
    s.stopped = !s.parent(s.fraction, s.stage);
    return s.stopped;
}

void on_geos_interrupt_check() {
    GeosInterrupt::State *s = active;
    if (s == nullptr)
        return; // GEOS used by another thread, or by GDAL outside a run
    if (!s->stopped && ++s->calls % calls_per_clock != 0)
        return;
    if (stop_requested(*s))
        GEOS_interruptRequest(); // also every later GEOS call of the run
}

} // namespace

GeosInterrupt::GeosInterrupt(Progress parent) {
    if (!parent)
        return;
    state_ = std::make_unique<State>();
    state_->parent = std::move(parent);
    state_->outer = active;
    state_->previous = GEOS_interruptRegisterCallback(&on_geos_interrupt_check);
    active = state_.get();
    State *s = state_.get();
    progress_ = [s](double f, std::string_view stage) {
        s->fraction = f;
        if (s->stage != stage)
            s->stage = std::string(stage);
        s->last_check = Clock::now();
        if (s->stopped)
            return false;
        if (!s->parent(f, stage))
            s->stopped = true;
        return !s->stopped;
    };
}

GeosInterrupt::~GeosInterrupt() {
    if (state_ == nullptr)
        return;
    GEOS_interruptRegisterCallback(state_->previous);
    GEOS_interruptCancel(); // a request nobody took
    active = state_->outer;
}

bool GeosInterrupt::interrupted() {
    return active != nullptr && active->stopped;
}

void GeosInterrupt::poll() {
    if (active != nullptr && stop_requested(*active))
        throw Cancelled();
}

} // namespace globemesh::coast
