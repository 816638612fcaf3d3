#pragma once
// An in-memory Modbus register bank: the answer a fake target gives. Holding and
// input registers share one table; a register never written reads as its address.
#include <cstdint>
#include <map>

#include "protocol/bytes.hpp"

namespace fieldbridge::northbound::modbus_tcp::test {

class RegisterBank {
public:
    /// Response PDU for @p request_pdu: FC03/04/06/10/17 served, coils and others
    /// 0x01, a malformed PDU 0x03.
    [[nodiscard]] protocol::Bytes answer(protocol::ByteView request_pdu);
    [[nodiscard]] std::uint16_t read(std::uint16_t address) const;

private:
    std::map<std::uint16_t, std::uint16_t> registers_;
};

}  // namespace fieldbridge::northbound::modbus_tcp::test
