// SPDX-License-Identifier: MIT
// dynaqpc host_sim transport: the msgpack format bytes the CAN datagram codec reads and writes
// (https://github.com/msgpack/msgpack/blob/master/spec.md, "Formats"). Private to vcan_codec.c.
#ifndef MSGPACK_TAGS_H
#define MSGPACK_TAGS_H

enum {
    MSGPACK_POSFIXINT_MAX = 0x7Fu, ///< 0xxxxxxx: the value itself, 0..127
    MSGPACK_FIXMAP = 0x80u,        ///< 1000nnnn: a map of n <= 15 pairs
    MSGPACK_FIXMAP_MASK = 0xF0u,
    MSGPACK_FIXSTR = 0xA0u,        ///< 101nnnnn: a string of n <= 31 bytes
    MSGPACK_FIXSTR_MASK = 0xE0u,
    MSGPACK_NIL = 0xC0u,
    MSGPACK_FALSE = 0xC2u,
    MSGPACK_TRUE = 0xC3u,
    MSGPACK_BIN8 = 0xC4u,          ///< bin 8, 16, 32: a 1, 2 or 4-byte length, then the bytes
    MSGPACK_BIN16 = 0xC5u,
    MSGPACK_BIN32 = 0xC6u,
    MSGPACK_FLOAT32 = 0xCAu,       ///< big-endian IEEE 754
    MSGPACK_FLOAT64 = 0xCBu,
    MSGPACK_UINT8 = 0xCCu,         ///< uint 8, 16, 32, 64: big-endian
    MSGPACK_UINT16 = 0xCDu,
    MSGPACK_UINT32 = 0xCEu,
    MSGPACK_UINT64 = 0xCFu,
    MSGPACK_INT8 = 0xD0u,          ///< int 8, 16, 32, 64: big-endian two's complement
    MSGPACK_INT64 = 0xD3u,
    MSGPACK_STR8 = 0xD9u,          ///< str 8, 16, 32: a 1, 2 or 4-byte length, then the bytes
    MSGPACK_STR16 = 0xDAu,
    MSGPACK_STR32 = 0xDBu,
    MSGPACK_MAP16 = 0xDEu,         ///< map 16, 32: a 2 or 4-byte pair count
    MSGPACK_MAP32 = 0xDFu,
    MSGPACK_NEGFIXINT = 0xE0u,     ///< 111xxxxx: -32..-1
};

#endif // MSGPACK_TAGS_H
