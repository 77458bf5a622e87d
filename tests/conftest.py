"""Test set-up: facadecli first, so that its BLAS settings come before numpy is loaded;
the slowest tests are marked ``slow`` (``make test-fast`` leaves them out)."""

import pytest

import facadecli  # noqa: F401

# test functions that take 0.3 s or more (``pytest --durations=100``, every parameter summed):
# whole commands in a subprocess, large façades, searches, external tools. A renamed test
# drops off this list and runs in ``make test-fast`` too, which is the safe side.
SLOW = {
    "test_geometry.py::test_every_example_passes_the_khronos_validator",  # make test installs it
    "test_cga.py::test_facade_grammar_writes_the_cga_beside_the_grammar",
    "test_city.py::test_a_dask_cluster_gives_the_same_files_as_local_processes",
    "test_city.py::test_a_small_city_builds_and_resumes",
    "test_city_assets.py::test_buildings_share_one_material_of_each_kind_and_each_picture",
    "test_city_assets.py::test_merging_the_same_buildings_twice_gives_the_same_bytes",
    "test_city_assets.py::test_the_merged_city_passes_the_khronos_validator",
    "test_city_assets.py::test_rays_at_35_degrees_from_eight_directions_meet_every_building",
    "test_city_assets.py::test_roofs_wear_a_library_material",
    "test_city_assets.py::test_the_seed_varies_the_walls_and_the_same_seed_gives_the_same_bytes",
    "test_city_inputs.py::test_a_dense_footprint_is_simplified_and_gets_its_walls",
    "test_city_resume.py::test_a_resumed_run_keeps_every_figure_and_gives_the_same_bytes",
    "test_city_resume.py::test_an_edited_spec_or_tag_rebuilds_exactly_what_it_changes",
    "test_city_resume.py::test_kill_9_then_resume_gives_a_fresh_runs_files",
    "test_cityjson.py::test_cjio_reads_and_rewrites_the_document",
    "test_cli.py::test_gltf_is_json_and_a_buffer_that_load_back",
    "test_cli.py::test_grammar_writes_text_json_svg_and_a_report",
    "test_cli.py::test_schema_is_json_and_matches_the_checked_in_copy",
    "test_cli.py::test_solve_exit_codes",
    "test_cli.py::test_solve_is_deterministic",
    "test_cli.py::test_solve_retargets_and_picks_formats",
    "test_cli.py::test_solve_writes_the_report_and_the_elevation",
    "test_cli.py::test_validate_rejects_with_position_and_no_traceback",
    "test_cli.py::test_vary_writes_each_variant_and_a_contact_sheet",
    "test_cli.py::test_version_imports_no_pydantic_and_solving_no_cvxpy_nor_trimesh",
    "test_cli.py::test_words_previews_each_layer",
    "test_exact.py::test_a_path_with_an_empty_piece_is_left_for_the_one_without",
    "test_exact.py::test_every_planted_layout_is_found_with_zero_deviation",
    "test_exact.py::test_the_same_search_twice_takes_the_same_steps",
    "test_exact.py::test_the_exact_search_finds_the_oracles_optimum",
    "test_fuzz.py::test_mutated_geojson_builds_rejects_or_fails_with_its_place",
    "test_fuzz.py::test_mutated_layouts_give_a_grammar_or_fail_with_their_place",
    "test_fuzz.py::test_mutated_specs_that_validate_solve_whole_or_not_at_all",
    "test_fuzz.py::test_mutated_specs_validate_or_fail_with_their_place",
    "test_geometry.py::test_no_ray_at_35_degrees_passes_through_an_example",
    "test_grammar.py::test_a_single_terminal_is_a_grammar_too",
    "test_grammar.py::test_a_size_far_from_the_inputs_is_noted",
    "test_grammar.py::test_derived_glb_passes_the_khronos_validator",
    "test_grammar.py::test_grammar_derive_writes_layouts_through_the_writers",
    "test_grammar.py::test_grammar_points_at_broken_json",
    "test_grammar.py::test_grammar_rejects_bad_options",
    "test_grammar.py::test_greedy_method_and_the_report",
    "test_grammar.py::test_the_search_stops_at_its_time_limit_with_the_best_so_far",
    "test_grammar_inputs.py::test_more_rectangles_than_the_limit_are_refused_before_the_work",
    "test_infer.py::test_a_solved_example_infers_back",
    "test_infer.py::test_facade_infer_rejects_a_layout_without_elements",
    "test_infer.py::test_facade_infer_writes_a_valid_spec_and_its_report",
    "test_osm.py::test_facade_city_builds_the_same_from_an_extract",
    "test_pattern_properties.py::test_every_enumerated_word_is_accepted_and_remade",
    "test_retarget.py::test_every_facade_laid_out_anew_tiles_its_new_size",
    "test_roofs.py::test_awkward_outlines_never_raise",
    "test_roofs.py::test_random_outlines_get_closed_roofs",
    "test_s3db.py::test_a_bounded_stream_of_tasks_gives_the_same_files",
    "test_s3db.py::test_a_city_in_tiles",
    "test_s3db.py::test_a_seed_varies_layouts_and_colours_per_building",
    "test_s3db.py::test_a_wall_rule_gives_some_walls_another_facade",
    "test_s3db.py::test_colours_spec_keeps_the_spec_materials",
    "test_s3db.py::test_height_is_the_top_of_the_roof",
    "test_snapping.py::test_clusters_are_never_wider_than_the_tolerance_and_keep_the_order",
    "test_snapping.py::test_clusters_are_the_fewest_and_move_edges_least",
    "test_solver_properties.py::test_every_solved_layout_meets_the_rules",
    "test_style.py::test_the_grammar_report_lists_the_style_and_what_each_derived_layout_keeps",
    "test_usd.py::test_every_example_writes_a_stage_usd_opens",
    "test_variations.py::test_drawn_proportions_give_as_many_variations_as_asked_and_keep_the_style",
    "test_variations.py::test_every_variation_tiles_the_canvas_with_the_grammars_labels",
    "test_variations.py::test_n_variations_are_distinct_and_the_first_is_the_single_derivation",
    "test_variations.py::test_symmetric_input_stays_symmetric_in_every_variation",
    "test_variations.py::test_the_command_writes_each_variation_and_a_contact_sheet",
    "test_variations.py::test_variations_are_deterministic_per_seed_and_seeds_differ",
    "test_variations.py::test_variations_print_no_solver_warnings",
    "test_watch.py::test_an_error_shows_with_its_place_and_the_last_model_stays",
    "test_watch.py::test_the_page_follows_the_file",
}


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        path, _, name = item.nodeid.partition("::")
        if f"{path.removeprefix('tests/')}::{name.partition('[')[0]}" in SLOW:
            item.add_marker(pytest.mark.slow)
