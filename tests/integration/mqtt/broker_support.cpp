#include "broker_support.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include <mqtt/async_client.h>
#include "free_port.hpp"
#include "temp_dir.hpp"

extern char** environ;

namespace fbt {

namespace {

sockaddr_in loopback(int port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
}

}  // namespace

int free_port() { return fieldbridge::test::free_loopback_port(); }

bool wait_for_listener(int port, std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < until) {
        const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a = loopback(port);
        const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
        ::close(fd);
        if (ok) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds{20});
    }
    return false;
}

Mosquitto::Mosquitto(int port) : port_(port) {
    dir_ = fieldbridge::test::make_temp_dir("fb-mqtt-test").string();
    std::ofstream conf(dir_ + "/mosquitto.conf");
    conf << "listener " << port_ << " 127.0.0.1\n"
         << "allow_anonymous true\n"
         << "persistence false\n"
         << "log_dest none\n";
}

Mosquitto::~Mosquitto() {
    stop();
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
}

void Mosquitto::start() {
    if (pid_ > 0) return;
    const std::string conf = dir_ + "/mosquitto.conf";
    std::string program = "mosquitto";
    for (const char* candidate : {"/usr/sbin/mosquitto", "/usr/bin/mosquitto"}) {
        if (::access(candidate, X_OK) == 0) {
            program = candidate;
            break;
        }
    }
    std::vector<std::string> args{program, "-c", conf};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (::posix_spawnp(&pid_, program.c_str(), nullptr, nullptr, argv.data(), environ) != 0) {
        pid_ = -1;
        throw std::runtime_error("cannot start mosquitto (is it installed?)");
    }
    if (!wait_for_listener(port_, std::chrono::seconds{5})) {
        stop();
        throw std::runtime_error("mosquitto did not listen on port " + std::to_string(port_) + " within 5 s");
    }
}

void Mosquitto::stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds{2};
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
        if (std::chrono::steady_clock::now() > until) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, &status, 0);
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds{10});
    }
    pid_ = -1;
}

class Observer::Impl {
public:
    Impl(const std::string& uri, const std::string& filter)
        : client_(uri, "observer-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++)) {
        client_.set_message_callback([this](mqtt::const_message_ptr m) {
            const std::lock_guard lock(mutex_);
            got_.push_back(Received{m->get_topic(), m->to_string(), m->is_retained()});
            cv_.notify_all();
        });
        mqtt::connect_options options;
        options.set_clean_session(true);
        client_.connect(options)->wait_for(std::chrono::seconds{5});
        if (!client_.is_connected()) throw std::runtime_error("observer: cannot connect to " + uri);
        client_.subscribe(filter, 1)->wait_for(std::chrono::seconds{5});
    }
    ~Impl() {
        try {
            client_.disconnect()->wait_for(std::chrono::seconds{2});
        } catch (...) {
        }
    }

    mqtt::async_client client_;
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    std::vector<Received> got_;
    static inline int counter_ = 0;
};

Observer::Observer(const std::string& uri, const std::string& filter) : impl_(std::make_unique<Impl>(uri, filter)) {}
Observer::~Observer() = default;

void Observer::publish(const std::string& topic, const std::string& payload, bool retained) {
    impl_->client_.publish(topic, payload.data(), payload.size(), 1, retained)->wait_for(std::chrono::seconds{5});
}

std::optional<Received> Observer::wait_for(const std::string& topic, const std::function<bool(const Received&)>& match,
                                           std::chrono::milliseconds timeout, std::size_t from) {
    std::unique_lock lock(impl_->mutex_);
    std::optional<Received> found;
    impl_->cv_.wait_for(lock, timeout, [&] {
        for (std::size_t i = from; i < impl_->got_.size(); ++i) {
            if (impl_->got_[i].topic == topic && match(impl_->got_[i])) {
                found = impl_->got_[i];
                return true;
            }
        }
        return false;
    });
    return found;
}

std::vector<Received> Observer::messages() const {
    const std::lock_guard lock(impl_->mutex_);
    return impl_->got_;
}

std::size_t Observer::count() const {
    const std::lock_guard lock(impl_->mutex_);
    return impl_->got_.size();
}

}  // namespace fbt
