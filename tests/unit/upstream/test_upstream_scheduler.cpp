#include <doctest/doctest.h>

#include <memory>
#include <vector>

#include "northbound/upstream/upstream_scheduler.hpp"
#include "upstream_test_support.hpp"

using namespace fieldbridge;
using namespace fieldbridge::northbound::upstream;
using protocol::Bytes;
using fbtest::mode_read;
using std::chrono::milliseconds;

namespace {

const Bytes counter_select_1{0x10, 0x08, 0x83, 0x00, 0x02, 0x04, 0x00, 0x00, 0x00, 0x01};
const Bytes counter_read{0x03, 0x08, 0x83, 0x00, 0x06};
const Bytes stop_cmd{0x06, 0x4E, 0x20, 0x00, 0x01};
const Bytes speed_cmd{0x06, 0x4E, 0xE8, 0x00, 0x64};

/// Records every outcome by a label.
struct Log {
    std::vector<std::pair<std::string, UpstreamOutcome>> done;
    [[nodiscard]] UpstreamDone record(std::string label) {
        return [this, label](const UpstreamOutcome& o) { done.emplace_back(label, o); };
    }
};

struct Fixture {
    SchedulerSettings settings;
    std::unique_ptr<UpstreamScheduler> s;
    Log log;
    engine::TimePoint t0 = engine::Clock::now();

    explicit Fixture(SchedulerSettings st = long_holds()) : settings(st), s(std::make_unique<UpstreamScheduler>(st)) {}

    /// The idle lapse alone (the tests of the maximum hold set their own).
    static SchedulerSettings long_holds() {
        SchedulerSettings st;
        st.sequence_max_hold = std::chrono::hours{1};
        return st;
    }

    void submit(const std::string& label, std::uint64_t client, const Bytes& pdu, engine::TimePoint at,
                bool poll = false) {
        UpstreamRequest r;
        r.client = client;
        r.poll = poll;
        r.unit = core::UnitId{1};
        r.pdu = pdu;
        const Classified c = classify(pdu);
        REQUIRE(c.request);
        r.request_class = *c.request;
        if (poll) r.request_class.priority = engine::Priority::poll;
        r.done = log.record(label);
        s->submit(std::move(r), at);
    }
    /// Sends the next request and answers it with an echo-style reply at once.
    Bytes send_and_answer(engine::TimePoint at, Bytes reply = {}) {
        auto d = s->next(at);
        REQUIRE(d.has_value());
        if (reply.empty()) reply = d->pdu.size() >= 5 ? Bytes(d->pdu.begin(), d->pdu.begin() + 5) : d->pdu;
        CHECK(s->reply(d->transaction_id, d->unit, reply, at));
        return d->pdu;
    }
    void drain() {
        for (auto& c : s->take_completions()) c.done(c.outcome);
    }
    [[nodiscard]] std::vector<std::string> order() const {
        std::vector<std::string> out;
        for (const auto& d : log.done) out.push_back(d.first);
        return out;
    }
};

}  // namespace

TEST_CASE("commands go before reads, stops before commands, polls last unless aged") {
    Fixture f;
    f.submit("poll", 0, mode_read, f.t0, true);
    f.submit("read", 1, mode_read, f.t0);
    f.submit("speed", 2, speed_cmd, f.t0);
    f.submit("stop", 3, stop_cmd, f.t0);
    for (int i = 0; i < 4; ++i) f.send_and_answer(f.t0);
    f.drain();
    CHECK(f.order() == std::vector<std::string>{"stop", "speed", "read", "poll"});

    // A poll that waited a whole period competes with reads by arrival (rule 3).
    Fixture g;
    g.submit("poll", 0, mode_read, g.t0, true);
    g.submit("read", 1, mode_read, g.t0 + milliseconds{10});
    g.send_and_answer(g.t0 + g.settings.poll_period);
    g.send_and_answer(g.t0 + g.settings.poll_period);
    g.drain();
    CHECK(g.order() == std::vector<std::string>{"poll", "read"});
}

TEST_CASE("window: one outstanding by default; transaction IDs are unique and matched") {
    SchedulerSettings st;
    st.window = 3;
    Fixture f(st);
    for (int i = 0; i < 4; ++i) f.submit("r" + std::to_string(i), 1, mode_read, f.t0);
    auto a = f.s->next(f.t0);
    auto b = f.s->next(f.t0);
    auto c = f.s->next(f.t0);
    REQUIRE((a && b && c));
    CHECK_FALSE(f.s->next(f.t0));
    CHECK(a->transaction_id != b->transaction_id);
    CHECK(b->transaction_id != c->transaction_id);
    // Answers out of order reach their own requests; a wrong unit or unknown ID is dropped.
    CHECK_FALSE(f.s->reply(b->transaction_id, core::UnitId{7}, {0x03, 0x02, 0x00, 0x02}, f.t0));
    CHECK(f.s->reply(c->transaction_id, core::UnitId{1}, {0x03, 0x02, 0x00, 0x03}, f.t0));
    CHECK(f.s->reply(a->transaction_id, core::UnitId{1}, {0x03, 0x02, 0x00, 0x01}, f.t0));
    CHECK(f.s->reply(b->transaction_id, core::UnitId{1}, {0x03, 0x02, 0x00, 0x02}, f.t0));
    CHECK_FALSE(f.s->reply(b->transaction_id, core::UnitId{1}, {0x03, 0x02, 0x00, 0x02}, f.t0));
    f.drain();
    REQUIRE(f.log.done.size() == 3);
    CHECK(f.log.done[0].first == "r2");
    CHECK(f.log.done[0].second.response_pdu == Bytes{0x03, 0x02, 0x00, 0x03});
    CHECK(f.log.done[1].first == "r0");
    CHECK(f.log.done[2].first == "r1");

    Fixture one;
    one.submit("a", 1, mode_read, one.t0);
    one.submit("b", 1, mode_read, one.t0);
    CHECK(one.s->next(one.t0));
    CHECK_FALSE(one.s->next(one.t0));
}

TEST_CASE("timeouts, command TTL, queue limit, wrong function, connection loss") {
    SchedulerSettings st;
    st.queue_limit = 2;
    Fixture f(st);
    f.submit("read", 1, mode_read, f.t0);
    auto d = f.s->next(f.t0);
    REQUIRE(d);
    f.submit("cmd", 1, speed_cmd, f.t0);
    f.submit("read2", 1, mode_read, f.t0);
    f.submit("full", 1, mode_read, f.t0);  // two already wait
    REQUIRE(f.s->next_deadline());
    CHECK(*f.s->next_deadline() == f.t0 + st.response_timeout);
    f.s->tick(f.t0 + st.response_timeout);
    f.drain();
    // No reply: 0x0B; the command's TTL (1 s) passed while it waited: never sent.
    REQUIRE(f.log.done.size() == 3);
    CHECK(f.log.done[0].first == "full");
    CHECK(f.log.done[0].second.status == UpstreamStatus::queue_full);
    CHECK(f.log.done[1].first == "read");
    CHECK(f.log.done[1].second.status == UpstreamStatus::timeout);
    CHECK(f.log.done[2].first == "cmd");
    CHECK(f.log.done[2].second.status == UpstreamStatus::expired);
    CHECK(f.s->consecutive_timeouts() == 1);
    // The late reply finds nobody.
    CHECK_FALSE(f.s->reply(d->transaction_id, core::UnitId{1}, {0x03, 0x02, 0x00, 0x01}, f.t0));

    // A reply with another function code fails the request (0x0B).
    auto r2 = f.s->next(f.t0 + st.response_timeout);
    REQUIRE(r2);
    CHECK(f.s->reply(r2->transaction_id, core::UnitId{1}, {0x04, 0x02, 0x00, 0x01}, f.t0));
    f.drain();
    CHECK(f.log.done.back().first == "read2");
    CHECK(f.log.done.back().second.status == UpstreamStatus::timeout);

    // Connection lost: in flight 0x0B, queued 0x0A.
    f.submit("sent", 1, mode_read, f.t0);
    f.submit("waiting", 1, mode_read, f.t0);
    REQUIRE(f.s->next(f.t0));
    f.s->fail_all(UpstreamStatus::path_down, UpstreamStatus::timeout);
    f.drain();
    REQUIRE(f.log.done.size() == 6);
    CHECK(f.log.done[4].second.status == UpstreamStatus::timeout);
    CHECK(f.log.done[5].second.status == UpstreamStatus::path_down);
    CHECK(f.s->queued() == 0);
    CHECK(f.s->in_flight() == 0);
}

TEST_CASE("a counter sequence is not split by another client") {
    Fixture f;
    f.submit("A select", 1, counter_select_1, f.t0);
    f.submit("B select", 2, counter_select_1, f.t0);
    f.submit("B mode", 2, mode_read, f.t0);
    f.submit("A read", 1, counter_read, f.t0);
    f.send_and_answer(f.t0);  // A select: A holds the counter block
    CHECK(f.s->owner(Resource::counter_read) == std::optional<std::uint64_t>{1});
    // B's select waits although it is a command; B's unrelated read goes; then A's read.
    CHECK(f.send_and_answer(f.t0) == mode_read);
    CHECK(f.send_and_answer(f.t0, {0x03, 0x0C, 0, 0, 0, 1, 0, 0, 0, 0x0A, 0, 0, 0, 5}) == counter_read);
    CHECK_FALSE(f.s->owner(Resource::counter_read));
    CHECK(f.send_and_answer(f.t0) == counter_select_1);
    CHECK(f.s->owner(Resource::counter_read) == std::optional<std::uint64_t>{2});
    f.drain();
    CHECK(f.order() == std::vector<std::string>{"A select", "B mode", "A read", "B select"});
}

TEST_CASE("a client's own requests to a resource keep their order") {
    Fixture f;
    // Pipelined: read the old selection, then select another: the (command) select
    // must not overtake the read.
    f.submit("read", 1, counter_read, f.t0);
    f.submit("select", 1, counter_select_1, f.t0);
    f.submit("mode", 1, mode_read, f.t0);
    CHECK(f.send_and_answer(f.t0) == counter_read);
    CHECK(f.send_and_answer(f.t0) == counter_select_1);
    CHECK(f.send_and_answer(f.t0) == mode_read);
}

TEST_CASE("sequences end on refusal, lapse when idle, and end when the client closes") {
    Fixture f;
    f.submit("A select", 1, counter_select_1, f.t0);
    auto d = f.s->next(f.t0);
    REQUIRE(d);
    CHECK(f.s->owner(Resource::counter_read) == std::optional<std::uint64_t>{1});
    f.s->reply(d->transaction_id, core::UnitId{1}, {0x90, 0x02}, f.t0);  // refused: nothing selected
    CHECK_FALSE(f.s->owner(Resource::counter_read));

    f.submit("A select again", 1, counter_select_1, f.t0);
    f.send_and_answer(f.t0);
    f.submit("B read", 2, counter_read, f.t0);
    CHECK_FALSE(f.s->next(f.t0));  // waits for A
    const auto lapse = f.s->next_deadline();
    REQUIRE(lapse);
    CHECK(*lapse == f.t0 + f.settings.sequence_hold);
    f.s->tick(*lapse);
    CHECK_FALSE(f.s->owner(Resource::counter_read));
    CHECK(f.send_and_answer(*lapse) == counter_read);

    // Closing: the owner's queued requests vanish unanswered, the resource is free.
    f.drain();
    const auto answered = f.log.done.size();
    f.submit("C select", 3, counter_select_1, f.t0);
    f.send_and_answer(f.t0);
    f.submit("C read", 3, counter_read, f.t0);
    f.submit("C mode", 3, mode_read, f.t0);
    f.submit("D read", 4, counter_read, f.t0);
    auto in_flight = f.s->next(f.t0);  // C read (C owns the block)
    REQUIRE(in_flight);
    CHECK(in_flight->pdu == counter_read);
    f.s->client_closed(3);
    CHECK_FALSE(f.s->owner(Resource::counter_read));
    CHECK(f.s->reply(in_flight->transaction_id, core::UnitId{1}, {0x03, 0x0C, 0, 0, 0, 1, 0, 0, 0, 0x0A, 0, 0, 0, 5}, f.t0));
    CHECK(f.send_and_answer(f.t0) == counter_read);  // D
    f.drain();
    CHECK(f.log.done.size() == answered + 2);  // C select and D read; nothing more for C
    CHECK(f.log.done.back().first == "D read");
}

TEST_CASE("an upload holds the data source across frames until idle") {
    Fixture f;
    const Bytes setup{0x10, 0x75, 0x32, 0x00, 0x03, 0x06, 0x00, 0x64, 0x00, 0x06, 0x00, 0x23};
    const Bytes upload{0x10, 0x75, 0x35, 0x00, 0x02, 0x04, 0x00, 0x01, 0x00, 0x01};
    f.submit("A setup", 1, setup, f.t0);
    f.send_and_answer(f.t0);
    f.submit("B setup", 2, setup, f.t0);
    f.submit("A upload 1", 1, upload, f.t0);
    CHECK(f.send_and_answer(f.t0) == upload);
    const auto later = f.t0 + milliseconds{500};
    f.submit("A upload 2", 1, upload, later);
    CHECK(f.send_and_answer(later) == upload);
    CHECK(f.s->owner(Resource::source_upload) == std::optional<std::uint64_t>{1});
    // B's set-up is a command: its TTL (1 s) runs out before A's sequence lapses.
    f.s->tick(f.t0 + f.settings.command_ttl);
    f.drain();
    CHECK(f.log.done.back().first == "B setup");
    CHECK(f.log.done.back().second.status == UpstreamStatus::expired);
    f.s->tick(later + f.settings.sequence_hold);
    CHECK_FALSE(f.s->owner(Resource::source_upload));
}

namespace {
/// A scheduler with @p max_hold in which client 1 ("A") selected counter 1 at t0.
std::unique_ptr<Fixture> counter_held_by_a(milliseconds max_hold) {
    SchedulerSettings st;
    st.sequence_max_hold = max_hold;
    auto f = std::make_unique<Fixture>(st);
    f->submit("A select", 1, counter_select_1, f->t0);
    f->send_and_answer(f->t0);
    return f;
}
}  // namespace

TEST_CASE("a client that keeps re-selecting holds the counter at most sequence_max_hold") {
    auto f = counter_held_by_a(milliseconds{500});
    f->submit("B read", 2, counter_read, f->t0 + milliseconds{10});
    CHECK_FALSE(f->s->next(f->t0 + milliseconds{10}));  // held by A
    // A re-selects every 200 ms; that does not extend its hold past 500 ms.
    f->submit("A select 2", 1, counter_select_1, f->t0 + milliseconds{200});
    CHECK(f->send_and_answer(f->t0 + milliseconds{200}) == counter_select_1);
    f->submit("A select 3", 1, counter_select_1, f->t0 + milliseconds{400});
    CHECK(f->send_and_answer(f->t0 + milliseconds{400}) == counter_select_1);
    const auto lapse = f->s->next_deadline();
    REQUIRE(lapse);
    CHECK(*lapse == f->t0 + milliseconds{500});
    f->s->tick(*lapse);
    CHECK_FALSE(f->s->owner(Resource::counter_read));
    // A's next select came before B's read went out: it waits behind B all the same.
    f->submit("A select 4", 1, counter_select_1, *lapse);
    CHECK(f->send_and_answer(*lapse) == counter_read);
    CHECK(f->send_and_answer(*lapse) == counter_select_1);
    f->drain();
    CHECK(f->order() == std::vector<std::string>{"A select", "A select 2", "A select 3", "B read", "A select 4"});
}

TEST_CASE("a hold past sequence_max_hold ends when the owner's request in flight is answered") {
    auto f = counter_held_by_a(milliseconds{100});
    const SchedulerSettings& st = f->settings;
    f->submit("A select 2", 1, counter_select_1, f->t0 + milliseconds{90});
    const auto in_flight = f->s->next(f->t0 + milliseconds{90});
    REQUIRE(in_flight);
    f->submit("B read", 2, counter_read, f->t0 + milliseconds{95});
    // Past the maximum, but A's select is out: the deadline is its response timeout.
    const auto deadline = f->s->next_deadline();
    REQUIRE(deadline);
    CHECK(*deadline == f->t0 + milliseconds{90} + st.response_timeout);
    f->s->tick(f->t0 + milliseconds{150});
    CHECK(f->s->owner(Resource::counter_read) == std::optional<std::uint64_t>{1});
    CHECK(f->s->reply(in_flight->transaction_id, core::UnitId{1}, Bytes(counter_select_1.begin(), counter_select_1.begin() + 5),
                     f->t0 + milliseconds{160}));
    CHECK_FALSE(f->s->owner(Resource::counter_read));
    CHECK(f->send_and_answer(f->t0 + milliseconds{160}) == counter_read);
}
