// The bounded outbox: retained values coalesce, events are dropped oldest first.
#include <doctest/doctest.h>

#include "northbound/mqtt/outbox.hpp"

namespace fm = fieldbridge::northbound::mqtt;

TEST_CASE("outbox: a retained message replaces the one waiting for its topic, and moves to the back") {
    fm::Outbox box(8);
    box.put({"p/a/state", "1", 1, true});
    box.put({"p/a/alarm", "event", 1, false});
    box.put({"p/a/state", "2", 1, true});
    CHECK(box.size() == 2);
    CHECK(box.superseded() == 1);
    CHECK(box.take()->payload == "event");
    CHECK(box.take()->payload == "2");
    CHECK_FALSE(box.take());
}

TEST_CASE("outbox: events are kept in order; when full the oldest goes and is counted") {
    fm::Outbox box(3);
    for (int i = 0; i < 5; ++i) box.put({"p/d/cmd/result", std::to_string(i), 1, false});
    CHECK(box.size() == 3);
    CHECK(box.dropped() == 2);
    CHECK(box.take()->payload == "2");
    box.put_first({"p/status", "online", 1, true});
    CHECK(box.take()->payload == "online");
    CHECK(box.take()->payload == "3");
}

TEST_CASE("outbox: bounded in bytes; transient messages go first, retained state never for a transient one") {
    fm::Outbox box(100, 60);
    box.put({"p/a/state", "1", 1, true});                     // 10 bytes (topic + payload)
    box.put({"p/b/state", "1", 1, true});                     // 10
    box.put({"p/a/alarm", std::string(20, 'e'), 1, false});  // 29
    CHECK(box.bytes() == 49);
    // A transient message that cannot fit beside the retained states is dropped
    // itself, and drops nothing else.
    box.put({"p/a/cmd/result", std::string(30, 'x'), 1, false});  // 44
    CHECK(box.dropped() == 1);
    CHECK(box.size() == 3);
    CHECK(box.bytes() == 49);
    // One that fits once the older transient message is gone takes its place.
    box.put({"p/a/cmd/result", std::string(21, 'r'), 1, false});  // 35
    CHECK(box.dropped() == 2);
    CHECK(box.size() == 3);
    CHECK(box.bytes() == 55);
    // A message larger than the whole outbox is never taken.
    box.put({"p/c/state", std::string(100, 'y'), 1, true});
    CHECK(box.dropped() == 3);
    CHECK(box.bytes() == 55);
    // A retained state displaces transient messages first, then older retained ones.
    box.put({"p/c/state", std::string(41, 's'), 1, true});  // 50
    CHECK(box.dropped() == 5);
    CHECK(box.size() == 2);
    CHECK(box.bytes() == 60);
    CHECK(box.take()->topic == "p/b/state");
    CHECK(box.take()->topic == "p/c/state");
    CHECK(box.bytes() == 0);
}
