function g = golden(set_dir, name)
% GOLDEN  A golden file of the fitter (every field 0x-hex): poses (single n x 5), status
% (uint8 n x 1), bits (uint32 n x k) of the outputs, finite (logical n x 1).
fid = fopen(fullfile(set_dir, name), 'r');
if fid < 0
  error('needle:test', 'cannot open %s', fullfile(set_dir, name));
end
header = strsplit(strtrim(fgetl(fid)), ',');
cols = numel(header);
text = fread(fid, Inf, '*char')';
fclose(fid);
fields = regexp(text, '0x([0-9a-fA-F]+)', 'tokens');
hex = cellfun(@(c) c{1}, fields, 'UniformOutput', false);
table = reshape(uint32(hex2dec(hex)), cols, [])';
g.header = header;
g.poses = reshape(typecast(reshape(table(:, 1:5), 1, []), 'single'), [], 5);
g.status = uint8(table(:, 6));
g.bits = table(:, 7:end);
g.finite = all(isfinite(g.poses), 2);
end
