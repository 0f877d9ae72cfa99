/* sf_error.h — the closed list of StrideFix error codes.
 *
 * Every public sf_ function either cannot fail (void) or returns SF_OK (0) or one of the negative
 * codes below; nothing else. Bad *data* is not an error of the caller: decoders return a code so the
 * caller can count the frame in HEALTH and skip it (libcanard's habit). */
#ifndef SF_ERROR_H
#define SF_ERROR_H

#define SF_OK 0
#define SF_EINVAL (-1)       /* an argument breaks the function's contract (NULL, bad size) */
#define SF_ESYNTAX (-2)      /* input text is not in the expected syntax (e.g. candump -L line) */
#define SF_EUNKNOWN_ID (-3)  /* CAN id not described by board.dbc */
#define SF_ELENGTH (-4)      /* frame shorter than its DBC length (truncated) */
#define SF_ERANGE (-5)       /* a value is outside its documented range */
#define SF_ENOTSYNC (-6)     /* sample before the first BOARD_TIME frame: no board time yet */
#define SF_EDUPLICATE (-7)   /* sample repeats the previous sequence number */
#define SF_EIO (-8)          /* an operating-system read/write failed (errno has the detail) */
#define SF_ENOENT (-9)       /* a named file or interface does not exist */
#define SF_EUNSUPPORTED (-10) /* not available on this platform/kernel (e.g. no AF_CAN) */
#define SF_EFULL (-11)       /* a bounded queue or table is full; the item was dropped */
#define SF_ELATE (-12)       /* a sample arrived after a newer one of its stream (reordered) */
#define SF_ESEQ (-13)        /* a sequence number that claims more time than passed (corrupt) */
#define SF_EIMPLAUSIBLE (-14) /* a sample beyond full scale or a physically impossible jump */
#define SF_EINTR (-15)       /* a blocking read was interrupted by a signal; nothing was lost, call again */
#define SF_ECORRUPT (-16)    /* a file's framing cannot be trusted: the rest of it is refused */
#define SF_ENOTCLASSIC (-17) /* a well-formed CAN FD frame where only classic CAN is taken (not a board frame) */

/* Short English text for a code; never NULL. */
const char *sf_strerror(int code);

#endif
