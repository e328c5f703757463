// Verilator main of the bulk wrapper with clock "cxx" (sim/tb/bulk.py): cocotb's own
// main loop (cocotb 2.1 share/lib/verilator/verilator.cpp, BSD-3-Clause, Copyright cocotb
// contributors; tracing and coverage left out), plus the wrapper's clock, toggled here in
// compiled code instead of by a Verilog delay loop (--timing) or cocotb's Clock.
//
// The clock has a rising and a falling edge at every multiple of BULK_PERIOD (simulator
// ticks, set by bulk.py) while the wrapper is not paused (`done && start`, as the Verilog
// clock's `wait`). The cycles before cocotb's next timed callback run back to back
// (clk = 1, eval, clk = 0, eval), with no VPI call but the value-change check after each
// cycle; a value-change callback that fired (a cocotb edge trigger) returns to the
// ordinary time-step loop. An edge that falls on cocotb's deadline comes after cocotb's
// timed callbacks of that step (sim/tb/tb_bulk.py acts half a period off the edges).
#include <memory>

#include "Vtop.h"
#include "verilated.h"
#include "verilated_vpi.h"

#ifndef BULK_PERIOD
#error "BULK_PERIOD (the clock period in simulator ticks) must be defined"
#endif

static vluint64_t main_time = 0;

double sc_time_stamp() { return main_time; }

extern "C" {
void vlog_startup_routines_bootstrap(void);
}

static inline bool settle_value_callbacks() {
    bool cbs_called, again;
    cbs_called = again = VerilatedVpi::callValueCbs();
    while (again) again = VerilatedVpi::callValueCbs();
    return cbs_called;
}

static void wrap_up() { VerilatedVpi::callCbs(cbEndOfSimulation); }

static inline bool paused(const Vtop* top) { return top->done && top->start; }

static inline void cycle(Vtop* top) {
    top->clk = 1;
    top->eval();
    top->clk = 0;
    top->eval();
}

int main(int argc, char** argv) {
    Verilated::commandArgs(argc, argv);
    std::unique_ptr<Vtop> top(new Vtop(""));
    Verilated::fatalOnVpiError(false);  // otherwise it will fail on systemtf
    vlog_startup_routines_bootstrap();
    Verilated::addExitCb([](void*) { wrap_up(); }, nullptr);
    VerilatedVpi::callCbs(cbStartOfSimulation);
    settle_value_callbacks();
    const vluint64_t NONE = static_cast<vluint64_t>(~0ULL);
    top->clk = 0;

    while (!Verilated::gotFinish()) {
        // this time step, as in cocotb's main: evaluate, ReadWrite and ReadOnly callbacks
        do {
            do {
                top->eval_step();
                VerilatedVpi::clearEvalNeeded();
                VerilatedVpi::doInertialPuts();
                settle_value_callbacks();
            } while (VerilatedVpi::evalNeeded());
            VerilatedVpi::callCbs(cbReadWriteSynch);
            VerilatedVpi::doInertialPuts();
            settle_value_callbacks();
        } while (VerilatedVpi::evalNeeded());
        top->eval_end_step();
        VerilatedVpi::callCbs(cbReadOnlySynch);

        vluint64_t next = VerilatedVpi::cbNextDeadline();
        if (next == NONE) break;  // cocotb waits for nothing more: the end
        // the clock's cycles before cocotb's next deadline, back to back
        bool fired = false;
        vluint64_t edge = (main_time / BULK_PERIOD + 1) * BULK_PERIOD;
        while (edge < next && !paused(top.get()) && !Verilated::gotFinish()) {
            main_time = edge;
            cycle(top.get());
            edge += BULK_PERIOD;
            if (settle_value_callbacks() || VerilatedVpi::evalNeeded()) {
                fired = true;
                break;
            }
        }
        if (fired) continue;
        main_time = next;
        VerilatedVpi::callCbs(cbNextSimTime);
        settle_value_callbacks();
        VerilatedVpi::callTimedCbs();
        settle_value_callbacks();
        if (main_time % BULK_PERIOD == 0 && !paused(top.get())) {
            VerilatedVpi::doInertialPuts();  // cocotb's writes of this step reach the edge
            cycle(top.get());
            settle_value_callbacks();
        }
    }

    top->final();
    wrap_up();
    return Verilated::threadContextp()->errorCount() > 0 ? 1 : 0;
}
