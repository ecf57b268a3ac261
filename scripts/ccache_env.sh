# Sourced by the build scripts: compile through ccache when it is installed (scripts/setup.sh
# installs it). The cache lives outside the clone, in root's ~/.cache/ccache unless CCACHE_DIR
# says otherwise, so CI's fresh clone and the next session on the same machine reuse the objects
# of the last build. Paths under the clone are hashed relative to it (CCACHE_BASEDIR) and the
# working folder is not hashed, so a clone in another folder still hits.
# The settings go into the compiler launcher itself (`env VAR=... ccache`), not only into this
# shell's environment, so that running `ninja` by hand in a build folder caches objects that a
# clone elsewhere can use too.
# Sets the array ccache_args to the CMake arguments that turn it on (empty without ccache).
ccache_args=()
if command -v ccache >/dev/null; then
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)}
  export CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-true}
  # Three builds (release, sanitizers, fuzzing) of about 1 GiB each fit with room for a second
  # version of each.
  export CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-8G}
  launcher="env;CCACHE_BASEDIR=$CCACHE_BASEDIR;CCACHE_NOHASHDIR=$CCACHE_NOHASHDIR"
  launcher+=";CCACHE_MAXSIZE=$CCACHE_MAXSIZE;ccache"
  ccache_args=("-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher" "-DCMAKE_C_COMPILER_LAUNCHER=$launcher")
fi
