/* Whitespace splitting of one text line into words, in place (tokens.h). */
#include "tokens.h"

#include <stdbool.h>

/* True when c is one of the (at most TOKENS_BLANKS_MAX) characters of blanks. */
static bool tokens_is_blank(char c, const char *blanks)
{
    for (size_t k = 0; k < TOKENS_BLANKS_MAX && blanks[k] != '\0'; k++)
        if (c == blanks[k])
            return true;
    return false;
}

size_t tokens_split(char *line, size_t cap, const char *blanks, char comment, char **words,
                    size_t max_words)
{
    size_t n = 0;
    size_t i = 0;
    while (i < cap && line[i] != '\0') {
        if (tokens_is_blank(line[i], blanks)) {
            i++;
            continue;
        }
        if (comment != '\0' && line[i] == comment)
            break;
        if (n == max_words)
            return max_words + 1u;
        words[n++] = &line[i];
        while (i < cap && line[i] != '\0' && !tokens_is_blank(line[i], blanks))
            i++;
        if (i < cap && line[i] != '\0')
            line[i++] = '\0';
    }
    return n;
}
