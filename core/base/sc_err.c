/* sc_err.c: strings of the error vocabulary, generated from SC_ERR_LIST. */
#include "sc_err.h"

const char *sc_err_str(int err)
{
    switch (err) {
    case SC_OK:
        return "ok";
#define SC_ERR_STR_(name, value, text)                                                         \
    case (value):                                                                              \
        return (text);
        SC_ERR_LIST(SC_ERR_STR_)
#undef SC_ERR_STR_
    default:
        return "unknown error";
    }
}

const char *sc_err_name(int err)
{
    switch (err) {
    case SC_OK:
        return "SC_OK";
#define SC_ERR_NAME_(name, value, text)                                                        \
    case (value):                                                                              \
        return #name;
        SC_ERR_LIST(SC_ERR_NAME_)
#undef SC_ERR_NAME_
    default:
        return "SC_ERR_UNKNOWN";
    }
}
