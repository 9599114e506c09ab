/* sc_msds_kern.c: the portable variant of the MSDS substep (sc_msds_kern.inc). */
#define SC_MSDS_SUBSTEP_FN sc_msds_substep_generic
#include "sc_msds_kern.inc"
