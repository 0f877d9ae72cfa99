/* sf_error.c — text for the closed error list of sf_error.h. */
#include "sf_error.h"

const char *sf_strerror(const int code)
{
    switch (code) {
    case SF_OK: return "ok";
    case SF_EINVAL: return "invalid argument";
    case SF_ESYNTAX: return "bad syntax";
    case SF_EUNKNOWN_ID: return "unknown CAN id";
    case SF_ELENGTH: return "frame truncated (shorter than its DBC length)";
    case SF_ERANGE: return "value out of range";
    case SF_ENOTSYNC: return "no board time yet";
    case SF_EDUPLICATE: return "duplicate sequence number";
    case SF_EIO: return "I/O error";
    case SF_ENOENT: return "no such file or interface";
    case SF_EUNSUPPORTED: return "not supported here";
    case SF_EFULL: return "queue full";
    case SF_ELATE: return "sample arrived late (reordered)";
    case SF_ESEQ: return "sequence number implausible for the time elapsed (corrupt)";
    case SF_EIMPLAUSIBLE: return "sample beyond full scale or a physically impossible jump";
    case SF_EINTR: return "interrupted by a signal";
    case SF_ECORRUPT: return "corrupt framing, rest of the file refused";
    case SF_ENOTCLASSIC: return "a CAN FD frame, not a classic CAN frame";
    default: return "unknown error";
    }
}
