/* The one splitter of a text line into words, for every line-based reader (host/io's text
 * formats, argil scripts, scripted window input, sim scenarios). Cuts in place; freestanding,
 * no heap; every loop is bounded by the caller's buffer size. */
#ifndef ARGIL_TOKENS_H
#define ARGIL_TOKENS_H

#include <stddef.h>

#define TOKENS_BLANKS_MAX 8u            /* characters a blank set may hold */
#define TOKENS_SPACE_TAB " \t"          /* blanks of the file formats and scenarios */
#define TOKENS_C_SPACE " \t\n\v\f\r"    /* isspace() in the C locale */

/* Splits the NUL-terminated line (within its first cap bytes) into words separated by runs of
 * the characters in blanks, writing a NUL after each word; when comment is not '\0', a word
 * that starts with it ends the line. Stores up to max_words word starts in words and returns
 * how many words the line holds, or max_words + 1 when it holds more. */
size_t tokens_split(char *line, size_t cap, const char *blanks, char comment, char **words,
                    size_t max_words);

#endif
