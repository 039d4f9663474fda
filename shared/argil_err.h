/* One error enum for commands across argil: ARGIL_OK = 0, negative values name the failure. */
#ifndef ARGIL_ERR_H
#define ARGIL_ERR_H

typedef enum {
    ARGIL_OK = 0,
    ARGIL_ERR_ARG = -1,        /* an argument out of its documented range */
    ARGIL_ERR_NONFINITE = -2,  /* NaN or Inf where a finite number is required */
    ARGIL_ERR_FULL = -3,       /* a fixed-size queue or buffer has no room */
    ARGIL_ERR_EMPTY = -4,      /* nothing to read */
    ARGIL_ERR_STATE = -5,      /* not allowed in the current state */
    ARGIL_ERR_IO = -6,         /* an operating-system call failed (host side only) */
    ARGIL_ERR_PARSE = -7,      /* malformed input */
    ARGIL_ERR_NOMEM = -8       /* host side: an allocation failed */
} argil_err_t;

#endif
