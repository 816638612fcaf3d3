#include "engine/register_image.hpp"

#include <algorithm>
#include <utility>

namespace fieldbridge::engine {

namespace {

[[nodiscard]] auto lower_bound_of(const std::vector<RegisterEntry>& slots, std::uint16_t address) {
    return std::lower_bound(slots.begin(), slots.end(), address,
                            [](const RegisterEntry& e, std::uint16_t a) { return e.address < a; });
}

[[nodiscard]] auto lower_bound_of(std::vector<RegisterEntry>& slots, std::uint16_t address) {
    return std::lower_bound(slots.begin(), slots.end(), address,
                            [](const RegisterEntry& e, std::uint16_t a) { return e.address < a; });
}

/// How many addresses from @p address fit below 0x10000.
[[nodiscard]] std::size_t room_from(std::uint16_t address) noexcept {
    return std::size_t{0x10000} - address;
}

}  // namespace

std::string_view to_string(Quality quality) noexcept {
    switch (quality) {
        case Quality::unknown: return "unknown";
        case Quality::good: return "good";
        case Quality::stale: return "stale";
        case Quality::offline: return "offline";
    }
    return "unknown";
}

void RegisterImage::update(Table table, std::uint16_t address, std::span<const std::uint16_t> values,
                           TimePoint now) {
    const std::size_t count = std::min(values.size(), room_from(address));
    if (count == 0) {
        return;
    }
    const bool bits = is_bit_table(table);
    Slots& s = slots(table);
    ImageChange change{table, {}};

    auto it = lower_bound_of(s, address);
    const auto first = static_cast<std::size_t>(it - s.begin());
    // Fast path: every address already present and contiguous in the vector (the
    // common case once the device has been polled once).
    const bool all_present =
        first + count <= s.size() && s[first].address == address &&
        s[first + count - 1].address == static_cast<std::uint16_t>(address + count - 1);
    if (!all_present) {
        // Insert the missing addresses once, then fall into the fast path.
        Slots merged;
        merged.reserve(s.size() + count);
        merged.insert(merged.end(), s.begin(), it);
        std::size_t k = first;
        for (std::size_t i = 0; i < count; ++i) {
            const auto a = static_cast<std::uint16_t>(address + i);
            if (k < s.size() && s[k].address == a) {
                merged.push_back(s[k++]);
            } else {
                merged.push_back(RegisterEntry{a, 0, Quality::unknown, TimePoint{}});
            }
        }
        merged.insert(merged.end(), s.begin() + static_cast<std::ptrdiff_t>(k), s.end());
        s.swap(merged);
    }
    for (std::size_t i = 0; i < count; ++i) {
        RegisterEntry& e = s[first + i];
        const std::uint16_t v = bits ? static_cast<std::uint16_t>(values[i] != 0 ? 1 : 0) : values[i];
        if (e.value != v || e.quality != Quality::good) {
            change.addresses.push_back(e.address);
        }
        e.value = v;
        e.quality = Quality::good;
        e.updated = now;
    }
    if (!change.addresses.empty()) {
        notify(change);
    }
}

void RegisterImage::mark_stale(Table table, std::uint16_t address, std::uint16_t count) {
    Slots& s = slots(table);
    ImageChange change{table, {}};
    const std::size_t end = std::size_t{address} + std::min<std::size_t>(count, room_from(address));
    for (auto it = lower_bound_of(s, address); it != s.end() && it->address < end; ++it) {
        if (it->quality == Quality::good) {
            it->quality = Quality::stale;
            change.addresses.push_back(it->address);
        }
    }
    if (!change.addresses.empty()) {
        notify(change);
    }
}

void RegisterImage::adopt(const RegisterImage& other) {
    tables_ = other.tables_;
    offline_ = other.offline_;
    for (std::size_t t = 0; t < table_count; ++t) {
        const Slots& s = tables_[t];
        if (s.empty()) continue;
        ImageChange change{static_cast<Table>(t), {}};
        change.addresses.reserve(s.size());
        for (const RegisterEntry& e : s) change.addresses.push_back(e.address);
        notify(change);
    }
}

void RegisterImage::set_offline(bool offline) {
    if (offline == offline_) {
        return;
    }
    offline_ = offline;
    set_quality_all(offline ? Quality::offline : Quality::stale);
}

void RegisterImage::set_quality_all(Quality quality) {
    for (std::size_t t = 0; t < table_count; ++t) {
        ImageChange change{static_cast<Table>(t), {}};
        for (RegisterEntry& e : tables_[t]) {
            if (e.quality != quality) {
                e.quality = quality;
                change.addresses.push_back(e.address);
            }
        }
        if (!change.addresses.empty()) {
            notify(change);
        }
    }
}

bool RegisterImage::read_fresh_into(Table table, std::uint16_t address, std::span<std::uint16_t> out,
                                    TimePoint now, Duration max_age) const {
    if (offline_ || out.empty() || out.size() > room_from(address)) {
        return false;
    }
    const Slots& s = slots(table);
    const auto it = lower_bound_of(s, address);
    const auto first = static_cast<std::size_t>(it - s.begin());
    if (first + out.size() > s.size()) {
        return false;
    }
    for (std::size_t i = 0; i < out.size(); ++i) {
        const RegisterEntry& e = s[first + i];
        if (e.address != address + i || e.quality != Quality::good || now - e.updated >= max_age) {
            return false;
        }
        out[i] = e.value;
    }
    return true;
}

std::optional<std::vector<std::uint16_t>> RegisterImage::read_fresh(Table table, std::uint16_t address,
                                                                    std::uint16_t count, TimePoint now,
                                                                    Duration max_age) const {
    std::vector<std::uint16_t> values(count);
    if (!read_fresh_into(table, address, values, now, max_age)) {
        return std::nullopt;
    }
    return values;
}

const RegisterEntry* RegisterImage::find(Table table, std::uint16_t address) const {
    const Slots& s = slots(table);
    const auto it = lower_bound_of(s, address);
    return it != s.end() && it->address == address ? &*it : nullptr;
}

std::optional<RegisterEntry> RegisterImage::get(Table table, std::uint16_t address) const {
    const RegisterEntry* e = find(table, address);
    return e != nullptr ? std::optional<RegisterEntry>{*e} : std::nullopt;
}

std::optional<std::uint16_t> RegisterImage::value(Table table, std::uint16_t address) const {
    const RegisterEntry* e = find(table, address);
    return e != nullptr ? std::optional<std::uint16_t>{e->value} : std::nullopt;
}

Quality RegisterImage::quality(Table table, std::uint16_t address) const {
    const RegisterEntry* e = find(table, address);
    return e != nullptr ? e->quality : Quality::unknown;
}

std::span<const RegisterEntry> RegisterImage::entries(Table table) const noexcept {
    return slots(table);
}

std::vector<RegisterEntry> RegisterImage::snapshot(Table table) const {
    return slots(table);
}

RegisterImage::SubscriptionId RegisterImage::subscribe(Listener listener) {
    const SubscriptionId id = next_id_++;
    subscribers_.push_back(Subscriber{id, std::move(listener)});
    return id;
}

bool RegisterImage::unsubscribe(SubscriptionId id) {
    const auto it = std::find_if(subscribers_.begin(), subscribers_.end(),
                                 [id](const Subscriber& s) { return s.id == id && s.active; });
    if (it == subscribers_.end()) {
        return false;
    }
    if (notifying_ > 0) {
        // notify() is walking the vector by index and may be inside this very
        // listener: deactivate it now, erase it when the walk is over.
        it->active = false;
        prune_pending_ = true;
    } else {
        subscribers_.erase(it);
    }
    return true;
}

void RegisterImage::notify(const ImageChange& change) {
    struct Depth {
        RegisterImage& image;
        explicit Depth(RegisterImage& i) : image(i) { ++image.notifying_; }
        ~Depth() {
            if (--image.notifying_ == 0 && image.prune_pending_) {
                image.prune_pending_ = false;
                std::erase_if(image.subscribers_, [](const Subscriber& s) { return !s.active; });
            }
        }
        Depth(const Depth&) = delete;
        Depth& operator=(const Depth&) = delete;
    };
    const Depth depth{*this};
    // By index and up to the size at entry: listeners may subscribe (push_back may
    // reallocate, so no reference is held across a call) or unsubscribe while we walk.
    const std::size_t n = subscribers_.size();
    for (std::size_t i = 0; i < n; ++i) {
        // Empty while it runs: a listener that changes the image is not called
        // back for its own change.
        if (subscribers_[i].active && subscribers_[i].listener) {
            // Moved out for the call: a push_back from inside the listener may move
            // the vector, and the function object must not move while it runs.
            Listener listener = std::move(subscribers_[i].listener);
            listener(change);
            subscribers_[i].listener = std::move(listener);
        }
    }
}

}  // namespace fieldbridge::engine
