function out_dir = build_needle_mex()
% BUILD_NEEDLE_MEX  Builds the needle_haptics MEX function (needle_haptics.c) over the
% C API and adds its folder to the path: cargo builds libneedle_capi.a and the needle
% command, `needle header` writes needle.h, then Octave's `mkoctfile --mex` or MATLAB's
% `mex` compiles and links. The MEX file lands in <repo>/target/bindings-matlab.
%
%   octave --eval "run crates/bindings-matlab/build_needle_mex.m"
%
% cargo's profile is the environment's NEEDLE_CARGO_PROFILE (default release; .ci/test
% passes ci, the profile its workspace tests built).
here = fileparts(mfilename('fullpath'));
root = fullfile(here, '..', '..');
target = fullfile(root, 'target');
out_dir = fullfile(target, 'bindings-matlab');
inc = fullfile(out_dir, 'include');
profile = getenv('NEEDLE_CARGO_PROFILE');
if isempty(profile)
  profile = 'release';
end
run_or_fail(sprintf('cd "%s" && cargo build --profile %s -q -p needle-capi -p needle-cli', root, profile));
run_or_fail(sprintf('"%s" header --out "%s"', fullfile(target, profile, 'needle'), inc));
lib = fullfile(target, profile, 'libneedle_capi.a');
src = fullfile(here, 'needle_haptics.c');
% One list of flags for both compilers: the header's folder, the source, the C API's
% static library and what a Rust static library needs on Linux (threads, dl, libm).
flags = {['-I' inc], src, lib, '-lpthread', '-ldl', '-lm'};
if exist('OCTAVE_VERSION', 'builtin')
  [text, status] = mkoctfile('--mex', flags{:}, '-o', fullfile(out_dir, 'needle_haptics.mex'));
  if status ~= 0
    error('needle:build', 'mkoctfile --mex failed (%d):\n%s', status, text);
  end
else
  % MATLAB's mex: the same flags; it names the file after the source
  % (needle_haptics.mexa64 on Linux) in -outdir. Not run in CI (no MATLAB there).
  mex(flags{:}, '-outdir', out_dir);
end
addpath(out_dir);
fprintf('built %s\n', fullfile(out_dir, 'needle_haptics'));
end

function run_or_fail(cmd)
[status, text] = system(cmd);
if status ~= 0
  error('needle:build', '%s failed (%d):\n%s', cmd, status, text);
end
end
