function fig8_validation(out_png)
% FIG8_VALIDATION  The paper's Fig. 8 style: the axial force Fy against depth at the
% Table 2 poses, the FE runs (points, coeffs/<set>/fe/<pose>.csv) and the model through
% the MEX function (lines). Writes out_png (default fig8_validation.png).
%
%   addpath target/bindings-matlab crates/bindings-matlab/examples
%   fig8_validation('fig8.png')
if nargin < 1
  out_png = 'fig8_validation.png';
end
here = fileparts(mfilename('fullpath'));
fe_dir = fullfile(here, '..', '..', '..', 'coeffs', 'default', 'fe');
runs = table2_runs(fullfile(fe_dir, 'manifest.toml'));
if isempty(runs)
  error('needle:example', 'no Table 2 run in %s', fe_dir);
end
if exist('OCTAVE_VERSION', 'builtin') && isempty(getenv('DISPLAY'))
  graphics_toolkit('gnuplot');  % no display: gnuplot draws the PNG
end
f = figure('visible', 'off');
hold on;
colors = lines(numel(runs));
for i = 1:numel(runs)
  r = runs(i);
  fe = dlmread(fullfile(fe_dir, [r.name '.csv']), ',', 1, 0);  % depth_mm, fx_n, fy_n, ...
  depth = linspace(0, 6, 121)';
  poses = single([repmat([r.x_mm r.z_mm r.theta_x_deg r.theta_z_deg], numel(depth), 1), depth]);
  wrench = needle_haptics('wrench', poses);
  plot(depth, wrench(:, 2), '-', 'Color', colors(i, :), 'LineWidth', 1.5);
  plot(fe(:, 1), fe(:, 3), 'o', 'Color', colors(i, :), 'MarkerSize', 4);
  labels{2 * i - 1} = sprintf('model %s (x %g, z %g, \\theta_x %g, \\theta_z %g)', r.name, r.x_mm, r.z_mm, r.theta_x_deg, r.theta_z_deg);
  labels{2 * i} = sprintf('FE %s', r.name);
end
xlabel('depth_mm', 'Interpreter', 'none');
ylabel('fy_n (N)', 'Interpreter', 'none');
title('Fy against depth at the Table 2 poses: FE (points), model (lines)');
legend(labels, 'Location', 'northwest');
grid on;
print(f, out_png, '-dpng', '-r100');
close(f);
fprintf('wrote %s\n', out_png);
end

function runs = table2_runs(manifest)
% The [pose.<name>] tables of fe/manifest.toml whose role is "table2": name and pose.
text = fileread(manifest);
blocks = regexp(text, '\[pose\.([^\]]+)\]([^\[]*)', 'tokens');
runs = struct('name', {}, 'x_mm', {}, 'z_mm', {}, 'theta_x_deg', {}, 'theta_z_deg', {});
for b = blocks
  body = b{1}{2};
  if isempty(regexp(body, 'role = "table2"', 'once'))
    continue;
  end
  r.name = b{1}{1};
  for key = {'x_mm', 'z_mm', 'theta_x_deg', 'theta_z_deg'}
    v = regexp(body, ['\n' key{1} ' = ([-0-9.eE+]+)'], 'tokens', 'once');
    r.(key{1}) = str2double(v{1});
  end
  runs(end + 1) = r;
end
end
