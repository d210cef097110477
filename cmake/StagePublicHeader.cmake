# cmake -DIN=src -DOUT=dst -P StagePublicHeader.cmake: copies a public header, its includes of
# other vtbake headers rewritten to the installed <vtbake/...> form.
file(READ "${IN}" text)
string(REGEX REPLACE "#include \"((common|codec|format|runtime)/[^\"]+)\"" "#include \"vtbake/\\1\""
                     text "${text}")
file(WRITE "${OUT}" "${text}")
