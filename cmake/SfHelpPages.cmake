# Generates a man page and a bash completion script for one of the suite's executables
# from its own --help (the top level and every subcommand's), so both always match the
# program. Run at build time (cmake/SfInstall.cmake):
#
#   cmake -DEXE=path/to/gsa -DNAME=gsa -DVERSION=0.1.0 -DMAN=out/gsa.1
#         -DCOMPLETION=out/gsa -P cmake/SfHelpPages.cmake
#
# The help text is CLI11's: "Usage: ..." line, then sections "Positionals:", "Options:",
# "Subcommands:" whose entries start with two spaces (name column, then description;
# a long name puts its description on the following, deeper indented line).

foreach(v EXE NAME VERSION MAN COMPLETION)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "SfHelpPages.cmake: -D${v}=... is required")
  endif()
endforeach()

function(run_help out_var)
  execute_process(COMMAND ${EXE} ${ARGN} --help OUTPUT_VARIABLE text ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${EXE} ${ARGN} --help failed (${rc}): ${err}")
  endif()
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()

# roff-escapes one line of text: backslashes, hyphens, and a leading dot or quote.
function(roff_escape out_var text)
  string(REPLACE "@SF_SEMICOLON@" ";" text "${text}")
  string(REPLACE "\\" "\\e" text "${text}")
  string(REPLACE "-" "\\-" text "${text}")
  if(text MATCHES "^[.']")
    set(text "\\&${text}")
  endif()
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()

# Splits a help text into: <prefix>_DESCRIPTION (lines before "Usage:"), <prefix>_USAGE,
# and per section ("Positionals", "Options", "Subcommands") two lists of the same length:
# <prefix>_<Section>_NAMES and <prefix>_<Section>_DESCS.
function(parse_help prefix text)
  string(REPLACE ";" "@SF_SEMICOLON@" text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(description "")
  set(usage "")
  set(section "")
  foreach(s Positionals Options Subcommands)
    set(${s}_names "")
    set(${s}_descs "")
  endforeach()
  set(pending_name "")
  foreach(line IN LISTS lines)
    if(line MATCHES "^Usage: (.*)$")
      set(usage "${CMAKE_MATCH_1}")
      set(section "")
    elseif(line MATCHES "^(Positionals|Options|Subcommands):[ ]*$")
      set(section "${CMAKE_MATCH_1}")
    elseif(section STREQUAL "" AND usage STREQUAL "" AND NOT line STREQUAL "")
      string(APPEND description "${line}\n")
    elseif(NOT section STREQUAL "" AND line MATCHES "^  ([^ ].*)$")
      set(entry "${CMAKE_MATCH_1}")
      if(pending_name AND entry MATCHES "^ ")
        set(entry "")
      endif()
      # Name column and description are separated by two or more spaces.
      if(entry MATCHES "^(.*[^ ])   *([^ ].*)$")
        list(APPEND ${section}_names "${CMAKE_MATCH_1}")
        list(APPEND ${section}_descs "${CMAKE_MATCH_2}")
        set(pending_name "")
      elseif(NOT entry STREQUAL "")
        set(pending_name "${entry}")
      endif()
    elseif(NOT section STREQUAL "" AND pending_name AND line MATCHES "^ +([^ ].*)$")
      list(APPEND ${section}_names "${pending_name}")
      list(APPEND ${section}_descs "${CMAKE_MATCH_1}")
      set(pending_name "")
    endif()
  endforeach()
  if(pending_name)
    list(APPEND ${section}_names "${pending_name}")
    list(APPEND ${section}_descs " ")
  endif()
  set(${prefix}_DESCRIPTION "${description}" PARENT_SCOPE)
  set(${prefix}_USAGE "${usage}" PARENT_SCOPE)
  foreach(s Positionals Options Subcommands)
    set(${prefix}_${s}_NAMES "${${s}_names}" PARENT_SCOPE)
    set(${prefix}_${s}_DESCS "${${s}_descs}" PARENT_SCOPE)
  endforeach()
endfunction()

# roff .TP entries of one section; appends to out_var.
function(roff_entries out_var names descs)
  set(text "${${out_var}}")
  list(LENGTH names n)
  if(n EQUAL 0)
    set(${out_var} "${text}" PARENT_SCOPE)
    return()
  endif()
  math(EXPR last "${n} - 1")
  foreach(i RANGE ${last})
    list(GET names ${i} name)
    list(GET descs ${i} desc)
    roff_escape(name "${name}")
    roff_escape(desc "${desc}")
    string(APPEND text ".TP\n.B ${name}\n${desc}\n")
  endforeach()
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()

# The option words of a section's names ("-o,--out TEXT REQUIRED" -> -o --out).
function(option_words out_var names)
  set(words "")
  foreach(name IN LISTS names)
    string(REGEX REPLACE " .*$" "" flags "${name}")
    string(REPLACE "," ";" flags "${flags}")
    foreach(f IN LISTS flags)
      if(f MATCHES "^-")
        list(APPEND words "${f}")
      endif()
    endforeach()
  endforeach()
  string(REPLACE ";" " " words "${words}")
  set(${out_var} "${words}" PARENT_SCOPE)
endfunction()

run_help(top)
parse_help(TOP "${top}")
string(TOUPPER "${NAME}" upper)
string(STRIP "${TOP_DESCRIPTION}" top_desc)
# The one-line description: the top-level help's first line without "NAME — " in front.
string(REGEX REPLACE "\n.*" "" name_line "${top_desc}")
string(REGEX REPLACE "^${NAME} *(—|-+) *" "" name_line "${name_line}")
if(NAME STREQUAL "gsa")
  set(name_line "grid strain analysis of digitised sheet parts by surface fitting")
elseif(NAME STREQUAL "simform")
  set(name_line "nonlinear forming simulation of fibre-reinforced plies")
endif()

set(man ".\\\" Generated from '${NAME} --help' by cmake/SfHelpPages.cmake; do not edit.\n")
string(APPEND man ".TH ${upper} 1 \"\" \"sheetform ${VERSION}\" \"User Commands\"\n")
roff_escape(esc_name_line "${name_line}")
string(APPEND man ".SH NAME\n${NAME} \\- ${esc_name_line}\n")
roff_escape(u "${TOP_USAGE}")
string(APPEND man ".SH SYNOPSIS\n.B ${u}\n")
string(APPEND man ".SH DESCRIPTION\n")
roff_escape(d "${top_desc}")
string(APPEND man "${d}\n.PP\nEach subcommand prints its own help with\n.BR \"${NAME} COMMAND \\-\\-help\" .\n")
string(APPEND man ".SH OPTIONS\n")
roff_entries(man "${TOP_Options_NAMES}" "${TOP_Options_DESCS}")
string(APPEND man ".SH COMMANDS\n")

option_words(top_words "${TOP_Options_NAMES}")
set(subcommands "")
set(completion_cases "")
foreach(sub IN LISTS TOP_Subcommands_NAMES)
  list(APPEND subcommands "${sub}")
endforeach()
foreach(sub IN LISTS subcommands)
  run_help(sub_text ${sub})
  parse_help(SUB "${sub_text}")
  list(FIND TOP_Subcommands_NAMES "${sub}" idx)
  list(GET TOP_Subcommands_DESCS ${idx} sub_desc)
  roff_escape(sub_desc "${sub_desc}")
  roff_escape(u "${SUB_USAGE}")
  string(APPEND man ".SS \"${NAME} ${sub}\"\n${sub_desc}\n.PP\n.B ${u}\n")
  if(SUB_Positionals_NAMES)
    string(APPEND man ".PP\nArguments:\n")
    roff_entries(man "${SUB_Positionals_NAMES}" "${SUB_Positionals_DESCS}")
  endif()
  if(SUB_Options_NAMES)
    string(APPEND man ".PP\nOptions:\n")
    roff_entries(man "${SUB_Options_NAMES}" "${SUB_Options_DESCS}")
  endif()
  option_words(words "${SUB_Options_NAMES}")
  string(APPEND completion_cases "    ${sub}) words=\"${words}\" ;;\n")
endforeach()

string(APPEND man ".SH EXIT STATUS\n0 success; 1 bad input or a run that could not converge (the message on stderr names the file, line and column, or the step); 2 wrong usage.\n")
string(APPEND man ".SH FILES\nSample data: \\fIshare/sheetform/data/\\fR under the installation prefix (e.g. /usr/share/sheetform/data).\nDocumentation: \\fIshare/doc/sheetform/\\fR (usage.md, forming.md, batch.md, python.md).\n")
string(APPEND man ".SH SEE ALSO\n")
if(NAME STREQUAL "gsa")
  string(APPEND man ".BR simform (1)\n")
else()
  string(APPEND man ".BR gsa (1)\n")
endif()
file(WRITE "${MAN}" "${man}")

string(REPLACE ";" " " subcommand_words "${subcommands}")
string(MAKE_C_IDENTIFIER "${NAME}" fn)
file(WRITE "${COMPLETION}" "# bash completion for ${NAME}; generated from '${NAME} --help' by cmake/SfHelpPages.cmake.
_sf_${fn}() {
  local cur=\"\${COMP_WORDS[COMP_CWORD]}\" cmd=\"\" words i
  for ((i = 1; i < COMP_CWORD; i++)); do
    case \"\${COMP_WORDS[i]}\" in
      -*) ;;
      *) cmd=\"\${COMP_WORDS[i]}\"; break ;;
    esac
  done
  case \"\$cmd\" in
    \"\") words=\"${subcommand_words} ${top_words}\" ;;
${completion_cases}    *) words=\"\" ;;
  esac
  if [[ -z \"\$cmd\" || \"\$cur\" == -* ]]; then
    mapfile -t COMPREPLY < <(compgen -W \"\$words\" -- \"\$cur\")
  else
    mapfile -t COMPREPLY < <(compgen -f -- \"\$cur\")
  fi
}
complete -o default -o bashdefault -F _sf_${fn} ${NAME}
")
