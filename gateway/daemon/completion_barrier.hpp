#pragma once
/// @file completion_barrier.hpp
/// Waiting for several components: the readiness barrier (READY=1 once every
/// listener is up) and the stop barrier (exit once every component has finished
/// its work in flight) are both a CompletionBarrier.

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace fieldbridge::daemon {

/// Counts outstanding tickets. Each component that needs time takes a ticket
/// (expect()) and calls done() on it when its part is finished; the owner calls
/// arm() once every component had its chance to take one. The completion handler
/// runs exactly once: in arm() when nothing is outstanding, else in the done()
/// that releases the last ticket. Loop thread only (no locking).
class CompletionBarrier {
    struct State;

public:
    /// One outstanding part. Move-only. Destroying it without done() leaves the
    /// part outstanding (a component that vanished without saying it is ready has
    /// not become ready); pending() names it.
    class Ticket {
    public:
        Ticket() = default;  ///< an empty ticket; done() on it does nothing
        Ticket(const Ticket&) = delete;
        Ticket& operator=(const Ticket&) = delete;
        Ticket(Ticket&& other) noexcept;
        Ticket& operator=(Ticket&& other) noexcept;
        ~Ticket() = default;

        /// Marks this part finished. Idempotent; safe after the barrier is gone.
        void done();
        /// True until done() was called on a ticket from expect().
        [[nodiscard]] bool outstanding() const noexcept;

    private:
        friend class CompletionBarrier;
        Ticket(std::weak_ptr<State> state, std::size_t index) noexcept;
        std::weak_ptr<State> state_;
        std::size_t index_ = 0;
    };

    explicit CompletionBarrier(std::function<void()> on_complete);
    CompletionBarrier(const CompletionBarrier&) = delete;
    CompletionBarrier& operator=(const CompletionBarrier&) = delete;
    CompletionBarrier(CompletionBarrier&&) = delete;
    CompletionBarrier& operator=(CompletionBarrier&&) = delete;
    ~CompletionBarrier() = default;

    /// A ticket for the part named @p what (e.g. "Modbus TCP listener 0.0.0.0:502").
    /// Throws std::logic_error once the barrier has completed.
    [[nodiscard]] Ticket expect(std::string what);
    /// No more tickets will be taken before completion can be decided.
    void arm();

    [[nodiscard]] bool armed() const noexcept;
    [[nodiscard]] bool complete() const noexcept;
    /// Names of the outstanding parts, in the order they were expected.
    [[nodiscard]] std::vector<std::string> pending() const;

private:
    std::shared_ptr<State> state_;
};

}  // namespace fieldbridge::daemon
