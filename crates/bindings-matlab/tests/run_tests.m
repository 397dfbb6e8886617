function failed = run_tests()
% RUN_TESTS  The MEX function against the fitter's golden files (bit for bit), its error
% messages (row and column), the insertion against the library's command line, and the
% README's example. Prints one line per test and "octave: N passed, M failed"; ends
% Octave with exit status 1 when a test failed (called from .ci/test-octave).
here = fileparts(mfilename('fullpath'));
root = fullfile(here, '..', '..', '..');
addpath(here);
set_dir = fullfile(root, 'coeffs', 'default');
tests = {@() t_wrench_golden(set_dir), @() t_stiffness_golden(set_dir), @() t_nan_rows(set_dir), ...
         @t_shape_and_class_errors, @() t_insertion_cli(set_dir, 'liver'), ...
         @() t_insertion_cli(set_dir, fullfile(set_dir, 'calibrated', 'rig_skin_2mmps_t1.toml')), @() t_bad_tissue_file(set_dir), ...
         @() t_readme(root), @() t_fig8_example(root)};
names = {'wrench is bit-exact on every finite golden row', 'stiffness is bit-exact on every finite golden row', ...
         'every non-finite golden row names its row and column', 'shape and class errors name the column', ...
         'insertion equals needle eval --insertion tick by tick', ...
         'a tissue file loaded at run time equals needle eval --insertion FILE tick by tick', ...
         'a refused tissue file names its line', 'the README example prints its line', ...
         'the Fig. 8-style example draws its PNG'};
passed = 0; failed = 0;
for i = 1:numel(tests)
  try
    tests{i}();
    passed = passed + 1;
    fprintf('ok     %s\n', names{i});
  catch err
    failed = failed + 1;
    fprintf('FAILED %s: %s\n', names{i}, err.message);
  end
end
fprintf('octave: %d passed, %d failed\n', passed, failed);
end

function check(cond, varargin)
if ~cond
  error('needle:test', varargin{:});
end
end

function t_wrench_golden(set_dir)
g = golden(set_dir, 'golden-f32.csv');
check(sum(g.finite) > 4000, 'too few golden rows: %d', sum(g.finite));
[w, s] = needle_haptics('wrench', g.poses(g.finite, :));
check(isa(w, 'single') && isequal(size(w), [sum(g.finite), 6]), 'wrench: single n x 6');
ok = same_bits(g.bits(g.finite, :), w);
rows = find(g.finite);
check(all(ok), '%d rows differ, first file line %d', sum(~ok), rows(find(~ok, 1)) + 1);
check(isequal(s, g.status(g.finite)), 'status differs');
end

function t_stiffness_golden(set_dir)
g = golden(set_dir, 'golden-stiffness-f32.csv');
[w, k, s] = needle_haptics('stiffness', g.poses(g.finite, :));
ok = same_bits(g.bits(g.finite, :), k);
check(all(ok), '%d rows differ', sum(~ok));
check(isequal(s, g.status(g.finite)), 'status differs');
[w2, ~] = needle_haptics('wrench', g.poses(g.finite, :));
check(isequal(typecast(w(:), 'uint32'), typecast(w2(:), 'uint32')), 'the wrench of stiffness differs from wrench');
end

function t_nan_rows(set_dir)
g = golden(set_dir, 'golden-f32.csv');
bad = find(~g.finite);
check(~isempty(bad) && all(g.status(bad) == 128), 'the golden error rows have status 0x80');
names = {'x_mm', 'z_mm', 'theta_x_deg', 'theta_z_deg', 'depth_mm'};
for r = bad'
  poses = [g.poses(g.finite, :); g.poses(r, :)];
  col = find(~isfinite(g.poses(r, :)), 1);
  want = sprintf('poses(%d, %d) (%s) is', size(poses, 1), col, names{col});
  try
    needle_haptics('wrench', poses);
    error('needle:test', 'no error for golden row %d', r);
  catch err
    check(strcmp(err.identifier, 'needle:poses'), 'identifier %s', err.identifier);
    check(~isempty(strfind(err.message, want)), 'message "%s" lacks "%s"', err.message, want);
  end
end
end

function expect_error(f, pattern)
try
  f();
catch err
  check(~isempty(regexp(err.message, pattern, 'once')), 'message "%s" does not match "%s"', err.message, pattern);
  return;
end
error('needle:test', 'no error, expected "%s"', pattern);
end

function t_shape_and_class_errors()
expect_error(@() needle_haptics('wrench', single(zeros(3, 4))), 'has 4 columns, the pose has 5 .*column 5 is missing');
expect_error(@() needle_haptics('wrench', single(zeros(3, 6))), 'has 6 columns.*column 6 is one too many');
expect_error(@() needle_haptics('wrench', [0 0 0 0 0.1]), 'poses\(1, 5\) \(depth_mm\) = 0.10000000000000001 is not a single value');
expect_error(@() needle_haptics('wrench', [0 0 0 0 3]), 'every value is a single value');
expect_error(@() needle_haptics('wrench', int32([0 0 0 0 3])), 'poses is int32, the library takes single');
expect_error(@() needle_haptics('stiffness', single([0 0 0 0 3; 0 0 0 Inf 3])), 'poses\(2, 4\) \(theta_z_deg\) is Inf');
expect_error(@() needle_haptics('insertion', 'kidney', single([0 0 0 0 3])), 'no tissue stack ''kidney''');
expect_error(@() needle_haptics('insertion', 'liver', single([0 0 0 0 3; -Inf 0 0 0 3])), 'poses\(2, 1\) \(x_mm\) is -Inf');
end

function t_bad_tissue_file(set_dir)
text = fileread(fullfile(set_dir, 'calibrated', 'rig_skin_2mmps_t1.toml'));
bad = [tempname() '.toml'];
fid = fopen(bad, 'w');
fprintf(fid, '%s', regexprep(text, 'stiffness_scale = ', 'stiffness_scale = -', 'once'));
fclose(fid);
lines = strsplit(fileread(bad), "\n", "CollapseDelimiters", false);
line = find(strncmp(lines, 'stiffness_scale = -', 19), 1);
[~, name, ext] = fileparts(bad);
expect_error(@() needle_haptics('insertion', bad, single([0 0 0 0 3])), sprintf('%s%s:%d:.*stiffness_scale', name, ext, line));
delete(bad);
end

% The insertion through `stack` (a compiled-in name or a tissue file's path) against the
% library's command line, tick by tick.
function t_insertion_cli(set_dir, stack)
depth = [linspace(-1, 30, 6000), linspace(30, 12, 2000), linspace(12, 35, 3000), linspace(35, -1, 4000)]';
poses = single([repmat([1.5 -0.5 4 -2], numel(depth), 1), depth]);
[w, s, phase, punctures] = needle_haptics('insertion', stack, poses);
check(sum(punctures) >= 1, 'the path punctures');
csv_in = [tempname() '.csv'];
fid = fopen(csv_in, 'w');
fprintf(fid, 'time_s,x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm\n');
fprintf(fid, '%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n', [(0:numel(depth) - 1)' * 0.001, double(poses)]');
fclose(fid);
exe = getenv('NEEDLE_BIN');
check(~isempty(exe), 'NEEDLE_BIN must name the needle binary (.ci/test-octave sets it)');
[status, text] = system(sprintf('"%s" eval --set "%s" --poses "%s" --insertion "%s"', exe, set_dir, csv_in, stack));
delete(csv_in);
check(status == 0, 'needle eval failed: %s', text);
lines = strsplit(strtrim(text), "\n");
check(numel(lines) == numel(depth) + 1, '%d lines from needle eval', numel(lines));
header = strsplit(lines{1}, ',');
rows = cellfun(@(l) strsplit(l, ','), lines(2:end), 'UniformOutput', false);
rows = vertcat(rows{:});
comps = {'fx_n', 'fy_n', 'fz_n', 'mx_nmm', 'my_nmm', 'mz_nmm'};
for c = 1:6
  want = single(str2double(rows(:, strcmp(header, comps{c}))));
  differ = find(typecast(want, 'uint32') ~= typecast(w(:, c), 'uint32'), 1);
  check(isempty(differ), '%s differs at tick %d: %.9g vs %.9g', comps{c}, differ, want(max(differ, 1)), w(max(differ, 1), c));
end
want_status = uint8(hex2dec(strrep(rows(:, strcmp(header, 'status')), '0x', '')));
check(isequal(s, want_status), 'status differs');
check(isequal(double(punctures), str2double(rows(:, strcmp(header, 'punctures')))), 'punctures differ');
kinds = struct('approach', 0, 'deflecting', 256, 'cutting', 512, 'in_track', 768);
phase_text = strrep(rows(:, strcmp(header, 'phase')), '-', '_');
want_phase = zeros(numel(depth), 1);
for i = 1:numel(depth)
  parts = strsplit(phase_text{i}, ':');
  want_phase(i) = kinds.(parts{1});
  if numel(parts) > 1
    want_phase(i) = want_phase(i) + str2double(parts{2});
  end
end
check(isequal(double(phase), want_phase), 'phase differs');
end

function t_readme(root)
text = fileread(fullfile(root, 'README.md'));
section = regexp(text, '## From MATLAB and Octave\n(.*?)\n## ', 'tokens', 'once');
check(~isempty(section), 'README has no "From MATLAB and Octave" section');
code = regexp(section{1}, '```matlab\n(.*?)```', 'tokens', 'once');
shown = regexp(section{1}, '```text\n(.*?)```', 'tokens', 'once');
check(numel(strsplit(strtrim(code{1}), "\n")) <= 5, 'the README example stays five lines');
old = pwd();
cd(root);
got = evalc(code{1});
cd(old);
check(strcmp(strtrim(got), strtrim(shown{1})), 'printed "%s", the README shows "%s"', strtrim(got), strtrim(shown{1}));
end

function t_fig8_example(root)
addpath(fullfile(root, 'crates', 'bindings-matlab', 'examples'));
png = fullfile(root, 'target', 'bindings-matlab', 'fig8_validation.png');
if exist(png, 'file')
  delete(png);
end
evalc('fig8_validation(png)');
d = dir(png);
check(~isempty(d) && d.bytes > 1000, 'no PNG at %s', png);
end
