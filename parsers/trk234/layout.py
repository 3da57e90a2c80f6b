"""TRK-2-34 SFDU byte layouts (820-013 TRK-2-34, revision N and later) as numpy dtypes.

Every SFDU is big-endian: a 20-byte SFDU label, the aggregation and primary CHDOs
(12 bytes), a secondary CHDO chosen by the label's data description id (C123 uplink,
C124 downlink, C125 derived, C126 interferometric, C127 filtered) and a tracking-data
CHDO chosen by the primary CHDO's format code (0..17). Field names follow column 2 of
the SIS tables. Codes: uN unsigned, i4 signed, f4/f8 IEEE floats, Sn ASCII, Vn reserved
bytes (kept verbatim so a file re-writes bit for bit). Times in the secondary CHDO are
UTC (year, day of year, seconds of day).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

HEADER = """
    control_auth_id:S4 sfdu_version_id:S1 sfdu_class_id:S1 label_spare:V2 data_description_id:S4
    sfdu_length:u8 agg_chdo_type:u2 agg_chdo_length:u2 pri_chdo_type:u2 pri_chdo_length:u2
    mjr_data_class:u1 mnr_data_class:u1 mission_id:u1 format_code:u1"""
LABEL_BYTES = 20
HEADER_BYTES = 32

SECONDARY = {
    "C123": """
    orig_id:u1 last_modifier_id:u1 reserve1:V1 scft_id:u1 upl_rec_seq_num:u4 rec_seq_num:u4
    year:u2 doy:u2 sec:f8 rct_day:u2 rct_msec:u4 ul_dss_id:u1 ul_band:u1 ul_assembly_num:u1
    transmit_num:u1 transmit_stat:u1 transmit_mode:u1 cmd_modul_stat:u1 rng_modul_stat:u1
    fts_vld_flag:u1 reserve1a:V1 transmit_time_tag_delay:f8 ul_zheight_corr:f4 mod_day:u2
    mod_msec:u4 version_num:u1 sub_version_num:u1 sub_sub_version_num:u1 reserve1b:V1
    reserve4:V4""",
    "C124": """
    orig_id:u1 last_modifier_id:u1 reserve1:V1 scft_id:u1 dtt_rec_seq_num:u4 rec_seq_num:u4
    year:u2 doy:u2 sec:f8 rct_day:u2 rct_msec:u4 dl_dss_id:u1 dl_band:u1 dl_chan_num:u1
    prdx_mode:u1 ul_prdx_stn:u1 ul_band_dl:u1 array_delay:f8 fts_vld_flag:u1 carr_lock_stat:u1
    array_flag:u1 polarization:u1 diplxr_stat:u1 lna_num:u1 rf_if_chan_num:u1 if_num:u1
    rcv_time_tag_delay:f8 dl_zheight_corr:f4 vld_ul_stn:u1 vld_dop_mode:u1 vld_scft_coh:u1
    scft_transpd_lock:u1 scft_transpd_num:u1 reserve1a:V1 scft_osc_freq:f8 scft_transpd_delay:f8
    scft_transpd_turn_num:u4 scft_transpd_turn_den:u4 scft_twnc_stat:u1 scft_osc_type:u1
    mod_day:u2 mod_msec:u4 version_num:u1 sub_version_num:u1 sub_sub_version_num:u1
    lna_corr_value:u1 reserve4:V4""",
    "C125": """
    orig_id:u1 last_modifier_id:u1 reserve1:V1 scft_id:u1 rec_seq_num:u4 year:u2 doy:u2 sec:f8
    rct_day:u2 rct_msec:u4 stn_stream_src:u1 ul_band:u1 ul_assembly_num:u1 transmit_num:u1
    transmit_stat:u1 transmit_mode:u1 cmd_modul_stat:u1 rng_modul_stat:u1
    transmit_time_tag_delay:f8 ul_zheight_corr:f4 dl_dss_id:u1 reserve1a:V1 dl_chan_num:u1
    prdx_mode:u1 ul_prdx_stn:u1 ul_band_dl:u1 array_delay:f8 fts_vld_flag:u1 carr_lock_stat:u1
    array_flag:u1 lna_num:u1 rcv_time_tag_delay:f8 dl_zheight_corr:f4 vld_ul_stn:u1
    vld_dop_mode:u1 vld_scft_coh:u1 vld_dl_band:u1 scft_transpd_lock:u1 scft_transpd_num:u1
    reserve2:V2 scft_osc_freq:f8 scft_transpd_delay:f8 scft_transpd_turn_num:u4
    scft_transpd_turn_den:u4 scft_twnc_stat:u1 scft_osc_type:u1 mod_day:u2 mod_msec:u4
    cnt_time:f4 version_num:u1 sub_version_num:u1 sub_sub_version_num:u1 lna_corr_value:u1""",
    "C126": """
    orig_id:u1 last_modifier_id:u1 reserve1a:V1 scft_id:u1 rec_seq_num:u4 year:u2 doy:u2 sec:f8
    rct_day:u2 rct_msec:u4 ul_dss_id:u1 dl_dss_id:u1 dl_dss_id_2:u1 dl_band:u1 prdx_mode:u1
    ul_band:u1 rec_type:u1 source_type:u1 fts_vld_flag:u1 reserve1b:V1 array_flag:u1
    array_flag_2:u1 array_delay:f8 array_delay_2:f8 rcv_time_tag_delay:f8
    rcv_time_tag_delay_2:f8 mod_day:u2 mod_msec:u4 version_num:u1 sub_version_num:u1
    sub_sub_version_num:u1 reserve1c:V1 reserve8:V8""",
    "C127": """
    orig_id:u1 last_modifier_id:u1 reserve1:V1 scft_id:u1 rec_seq_num:u4 year:u2 doy:u2 sec:f8
    rct_day:u2 rct_msec:u4 dl_dss_id:u1 dl_band:u1 dl_chan_num:u1 prdx_mode:u1 ul_prdx_stn:u1
    ul_band_dl:u1 rcv_time_tag_delay:f8 array_delay:f8 fts_vld_flag:u1 carr_lock_stat:u1
    array_flag:u1 lna_num:u1 vld_ul_stn:u1 vld_dop_mode:u1 vld_scft_coh:u1 scft_transpd_lock:u1
    scft_transpd_num:u1 reserve1a:V1 scft_osc_freq:f8 scft_transpd_delay:f8
    scft_transpd_turn_num:u4 scft_transpd_turn_den:u4 scft_twnc_stat:u1 scft_osc_type:u1
    mod_day:u2 mod_msec:u4 version_num:u1 sub_version_num:u1 sub_sub_version_num:u1 reserve1b:V1
    reserve4:V4""",
}

TRACKING = {
    0: """
    ul_hi_phs_cycles:u4 ul_lo_phs_cycles:u4 ul_frac_phs_cycles:u4 ramp_freq:f8 ramp_rate:f8
    transmit_switch_stat:u1 ramp_type:u1 transmit_op_pwr:f4 sup_data_id:S8 sup_data_rev:S8
    prdx_time_offset:f8 prdx_freq_offset:f8 time_tag_corr_flag:u1 type_time_corr_flag:u1
    fabricated_sfdu_flag:u1 reserve1:V1 reserve6:V6""",
    1: """
    carr_loop_bw:f4 pcn0:f4 pcn0_resid:f4 pdn0:f4 pdn0_resid:f4 system_noise_temp:f4 phs_hi_0:u4
    phs_lo_0:u4 phs_frac_0:u4 phs_hi_1:u4 phs_lo_1:u4 phs_frac_1:u4 phs_hi_2:u4 phs_lo_2:u4
    phs_frac_2:u4 phs_hi_3:u4 phs_lo_3:u4 phs_frac_3:u4 phs_hi_4:u4 phs_lo_4:u4 phs_frac_4:u4
    phs_hi_5:u4 phs_lo_5:u4 phs_frac_5:u4 phs_hi_6:u4 phs_lo_6:u4 phs_frac_6:u4 phs_hi_7:u4
    phs_lo_7:u4 phs_frac_7:u4 phs_hi_8:u4 phs_lo_8:u4 phs_frac_8:u4 phs_hi_9:u4 phs_lo_9:u4
    phs_frac_9:u4 phs_hi_avg:u4 phs_lo_avg:u4 phs_frac_avg:u4 dl_freq:f8 dop_resid:f4
    dop_noise:f4 slipped_cycles:i4 carr_loop_type:u1 snt_flag:u1 carr_resid_wt:f4 sup_data_id:S8
    sup_data_rev:S8 prdx_time_offset:f8 prdx_freq_offset:f8 carr_resid_tol_flag:u1
    time_tag_corr_flag:u1 type_time_corr_flag:u1 dop_mode_corr_flag:u1 ul_stn_corr_flag:u1
    reserve1:V1 reserve8:V8""",
    2: """
    stn_cal:f8 ul_stn_cal:f8 ul_cal_freq:f8 cal_std_dev:f4 cal_pts:u2 ul_rng_phs:f8
    transmit_switch_stat:u1 invert:u1 transmit_op_pwr:f4 template_id:S8 t1:u2 t2:u2 t3:u2
    first_comp_num:u1 last_comp_num:u1 chop_comp_num:u1 num_drvid:u1 transmit_inphs_time_year:u2
    transmit_inphs_time_doy:u2 transmit_inphs_time_sec:f8 carr_sup_rng_modul:f4 rng_modul_amp:u2
    exc_scalar_num:u4 exc_scalar_den:u4 rng_cycle_time:f8 time_tag_corr_flag:u1
    type_time_corr_flag:u1 clock_waveform:u1 chop_start_num:u1 rng_meas_type:u1
    fabricated_sfdu_flag:u1 reserve6:V6""",
    3: """
    stn_cal:f8 dl_stn_cal:f8 dl_cal_freq:f8 cal_std_dev:f4 cal_pts:u2 dl_rng_phs:f8
    figure_merit:f4 rng_resid:f8 drvid:f8 rtlt:f4 pcn0:f4 pcn0_resid:f4 pdn0:f4 pdn0_resid:f4
    prn0:f4 prn0_resid:f4 system_noise_temp:f4 carr_loop_type:u1 snt_flag:u1 carr_resid_wt:f4
    template_id:S8 invert:u1 correl_type:u1 t1:u2 t2:u2 t3:u2 first_comp_num:u1 last_comp_num:u1
    chop_comp_num:u1 num_drvid:u1 rcv_inphs_time_year:u2 rcv_inphs_time_doy:u2
    rcv_inphs_time_sec:f8 exc_scalar_num:u4 exc_scalar_den:u4 rng_cycle_time:f8 inphs_correl:f4
    quad_phs_correl:f4 metrics_vld_flag:u1 correl_vld_flag:u1 rng_resid_tol_flag:u1
    drvid_tol_flag:u1 prn0_resid_tol_flag:u1 rng_sigma_tol_flag:u1 rng_vld_flag:u1
    rng_config_flag:u1 rng_hw_flag:u1 time_tag_corr_flag:u1 type_time_corr_flag:u1
    dop_mode_corr_flag:u1 ul_stn_corr_flag:u1 chop_start_num:u1 rng_meas_type:u1
    stn_cal_corr_flag:u1 reserve6:V6""",
    4: """
    stn_cal:f8 ul_stn_cal:f8 ul_cal_freq:f8 cal_std_dev:f4 cal_pts:u2 ul_rng_phs:f8
    state_subcode1:u1 state_subcode2:u1 state_subcode3:u1 state_subcode4:u1 state_subcode5:u1
    state_subcode6:u1 pn_clk_phs:f8 transmit_switch_stat:u1 invert:u1 transmit_op_pwr:f4
    template_id:S22 chip_rate:u1 len_subcode1:u1 len_subcode2:u1 len_subcode3:u1 len_subcode4:u1
    len_subcode5:u1 len_subcode6:u1 op_subcode1:u1 op_subcode2:u1 op_subcode3:u1 op_subcode4:u1
    op_subcode5:u1 def_subcode1:u8 def_subcode2:u8 def_subcode3:u8 def_subcode4:u8
    def_subcode5:u8 def_subcode6:u8 pn_code_length:u4 transmit_inphs_time_year:u2
    transmit_inphs_time_doy:u2 transmit_inphs_time_sec:f8 carr_sup_rng_modul:f4 rng_modul_amp:u2
    exc_scalar_num:u4 exc_scalar_den:u4 rng_cycle_time:f8 clock_waveform:u1 rng_meas_type:u1
    time_tag_corr_flag:u1 type_time_corr_flag:u1 fabricated_sfdu_flag:u1 op_subcode6:u1
    ccsds_k:u1 ccsds_l:u1 reserve4:V4""",
    5: """
    stn_cal:f8 dl_stn_cal:f8 dl_cal_freq:f8 cal_std_dev:f4 cal_pts:u2 dl_rng_phs:f8
    figure_merit:f4 rng_resid:f8 drvid:f8 rtlt:f4 pcn0:f4 pcn0_resid:f4 pdn0:f4 pdn0_resid:f4
    prn0:f4 prn0_resid:f4 system_noise_temp:f4 state_subcode1:u1 state_subcode2:u1
    state_subcode3:u1 state_subcode4:u1 state_subcode5:u1 state_subcode6:u1 pn_clk_phs:f8
    carr_loop_type:u1 snt_flag:u1 carr_resid_wt:f4 template_id:S20 invert:u1 correl_type:u1
    int_time:u4 chip_rate:u1 len_subcode1:u1 len_subcode2:u1 len_subcode3:u1 len_subcode4:u1
    len_subcode5:u1 len_subcode6:u1 op_subcode1:u1 op_subcode2:u1 op_subcode3:u1 op_subcode4:u1
    op_subcode5:u1 def_subcode1:u8 def_subcode2:u8 def_subcode3:u8 def_subcode4:u8
    def_subcode5:u8 def_subcode6:u8 pn_code_length:u4 rcv_inphs_time_year:u2
    rcv_inphs_time_doy:u2 rcv_inphs_time_sec:f8 exc_scalar_num:u4 exc_scalar_den:u4
    rng_cycle_time:f8 inphs_correl:f4 quad_phs_correl:f4 metrics_vld_flag:u1 correl_vld_flag:u1
    rng_resid_tol_flag:u1 drvid_tol_flag:u1 prn0_resid_tol_flag:u1 rng_sigma_tol_flag:u1
    rng_vld_flag:u1 rng_config_flag:u1 rng_hw_flag:u1 rng_meas_type:u1 time_tag_corr_flag:u1
    type_time_corr_flag:u1 dop_mode_corr_flag:u1 ul_stn_corr_flag:u1 stn_cal_corr_flag:u1
    op_subcode6:u1 ccsds_k:u1 ccsds_l:u1 reserve4:V4""",
    6: """
    ref_rcv_type:u1 reserve1a:V1 sampl_interval:f4 rcv_sig_lvl:f4 ul_freq:f8
    dop_cnt_bias_freq:f8 dop_cnt:f8 dop_pseudo_resid:f8 time_tag_corr_flag:u1
    type_time_corr_flag:u1 dop_mode_corr_flag:u1 ul_stn_corr_flag:u1 dl_band_corr_flag:u1
    dop_vld_flag:u1 reserve8:V8""",
    7: """
    ul_stn_cal:f8 dl_stn_cal:f8 meas_rng:f8 rng_obs:f8 rng_obs_dl:f8 clock_waveform:u1
    chop_start_num:u1 figure_merit:f4 drvid:f8 rtlt:f4 prn0:f4 transmit_pwr:f4 invert:u1
    correl_type:u1 t1:u2 t2:u2 t3:u2 first_comp_num:u1 last_comp_num:u1 chop_comp_num:u1
    num_drvid:u1 transmit_inphs_time:f4 rcv_inphs_time:f4 carr_sup_rng_modul:f4
    exc_scalar_num:u4 exc_scalar_den:u4 rng_cycle_time:f8 rng_modulo:u4 inphs_correl:f4
    quad_phs_correl:f4 ul_freq:f8 rng_type:u1 fabricated_ul_flag:u1 rng_noise:f4
    rng_prefit_resid:f8 rng_dl_prefit_resid:f8 rng_prefit_resid_vld_flag:u1
    rng_dl_prefit_resid_vld_flag:u1 rng_resid_tol_value:f4 drvid_tol_value:f4
    prn0_resid_tol_value:f4 rng_sigma_tol_value:f4 fom_tol_value:f4 rng_resid_tol_flag:u1
    drvid_tol_flag:u1 prn0_resid_tol_flag:u1 rng_sigma_tol_flag:u1 rng_vld_flag:u1
    rng_config_flag:u1 stn_cal_corr_flag:u1 rng_chan_num:u1 time_tag_corr_flag:u1
    type_time_corr_flag:u1 reserve6:V6""",
    8: """
    source_type:u1 ang_type:u1 ang_vld_flag:u1 ang_mode:u1 conscan_mode:u1 acq_aid_mode:u1
    ang1:f4 ang2:f4 ang1_pseudo_resid:f4 ang2_pseudo_resid:f4 time_tag_corr_flag:u1
    type_time_corr_flag:u1 reserve2:V2 reserve8:V8""",
    9: """
    ul_hi_phs_cycles:u4 ul_lo_phs_cycles:u4 ul_frac_phs_cycles:u4 ramp_freq:f8 ramp_rate:f8
    ramp_type:u1 fabricated_sfdu_flag:u1 reserve8:V8""",
    10: """
    clk_off_epoch_year:u2 clk_off_epoch_doy:u2 clk_off_epoch_sec:f8 clk_off_1:f4 clk_off_2:f4
    phs_cal_flag:u1 chan_sampl_flag:u1 quasar_id:S12 quasar_id_num:u2 data_qual_flag:u1
    freq_chan_num:u1 mode_id:u1 modulo_flag:u1 ref_freq:f8 modulus:f8 dod_cnt_time:f4 dod_obs:f8
    dor_obs:f8 reserve20:V20""",
    11: """
    drvid_type:u1 drvid_pts:u1 drvid:f8 prn0:f4 drvid_noise:f4 drvid_tol_value:f4
    prn0_resid_tol_value:f4 reserve1:V1 drvid_tol_flag:u1 prn0_resid_tol_flag:u1
    drvid_noise_pts:u1 reserve8:V8""",
    12: """
    sm_noise_01s:f4 sm_noise_1s:f4 sm_noise_10s:f4 sm_noise_100s:f4 sm_noise_200s:f4
    sm_noise_600s:f4 int_time:u4 percent_data_used:f4 new_01sec:u1 new_1sec:u1 new_10sec:u1
    new_100sec:u1 new_200sec:u1 new_600sec:u1 reserve8:V8""",
    13: """
    allan_dev_01s:f4 allan_dev_1s:f4 allan_dev_10s:f4 allan_dev_100s:f4 allan_dev_1000s:f4
    int_time:u4 percent_data_used:f4 rpt_cause:u1 new_01sec:u1 new_1sec:u1 new_10sec:u1
    new_100sec:u1 new_1000sec:u1 reserve8:V8""",
    14: """
    ul_stn_cal:f8 dl_stn_cal:f8 meas_rng:f8 rng_obs_dl:f8 figure_merit:f4 drvid:f8 rtlt:f4
    prn0:f4 transmit_pwr:f4 invert:u1 correl_type:u1 chip_rate:u1 len_subcode1:u1
    len_subcode2:u1 len_subcode3:u1 len_subcode4:u1 len_subcode5:u1 len_subcode6:u1
    op_subcode1:u1 op_subcode2:u1 op_subcode3:u1 op_subcode4:u1 op_subcode5:u1 def_subcode1:u8
    def_subcode2:u8 def_subcode3:u8 def_subcode4:u8 def_subcode5:u8 def_subcode6:u8
    pn_code_length:u4 transmit_inphs_time:f4 rcv_inphs_time:f4 carr_sup_rng_modul:f4
    exc_scalar_num:u4 exc_scalar_den:u4 rng_cycle_time:f8 rng_modulo:u4 rng_type:u1
    fabricated_ul_flag:u1 rng_noise:f4 rng_dl_prefit_resid:f8 rng_dl_prefit_resid_vld_flag:u1
    clock_waveform:u1 rng_resid_tol_value:f4 drvid_tol_value:f4 prn0_resid_tol_value:f4
    rng_sigma_tol_value:f4 fom_tol_value:f4 rng_resid_tol_flag:u1 drvid_tol_flag:u1
    prn0_resid_tol_flag:u1 rng_sigma_tol_flag:u1 rng_vld_flag:u1 rng_config_flag:u1
    stn_cal_corr_flag:u1 op_subcode6:u1 ccsds_k:u1 ccsds_l:u1 reserve4:V4""",
    15: """
    source_type:u1 mjr_tone_freq:u1 mnr_tone_freq:u1 rng_prefit_resid_vld_flag:u1 meas_rng:f8
    rng_obs:f8 stn_cal:f8 carr_pwr:f4 rng_prefit_resid:f8 ul_freq:f8 time_tag_corr_flag:u1
    type_time_corr_flag:u1""",
    16: """
    ref_rcv_type:u1 fabricated_ul_flag:u1 carr_prefit_resid_tol_value:f4 reserve2:V2
    dop_noise:f4 delta_ff:f8 rcv_sig_lvl:f4 num_obs:u2 obs_cnt_time:f4""",
    17: """
    ref_rcv_type:u1 fabricated_ul_flag:u1 total_cnt_phs_prefit_resid_tol_value:f4 reserve2:V2
    dop_noise:f4 delta_ff:f8 rcv_sig_lvl:f4 num_obs:u2 obs_cnt_time:f4 total_cnt_phs_st_year:u2
    total_cnt_phs_st_doy:u2 total_cnt_phs_st_sec:f8""",
}

# Repeated observation groups of the variable-length formats (16 and 17), followed by
# one trailing 8-byte reserve after the last group.
REPEATED = {
    16: "rcv_carr_obs:f8 carr_prefit_resid:f4 carr_prefit_resid_vld_flag:u1 carr_prefit_resid_tol_flag:u1 "
        "obs_reserve4:V4",
    17: "total_cnt_phs_obs_hi:u4 total_cnt_phs_obs_lo:u4 total_cnt_phs_obs_frac:u4 total_cnt_phs_prefit_resid:f4 "
        "total_cnt_phs_prefit_resid_vld_flag:u1 total_cnt_phs_prefit_resid_tol_flag:u1 obs_reserve4:V4",
}
TRAILER_BYTES = 8

# Data description id of each format code's secondary CHDO.
CLASS_OF_FORMAT = {0: "C123", 1: "C124", 2: "C123", 3: "C124", 4: "C123", 5: "C124", 6: "C125", 7: "C125",
                   8: "C125", 9: "C123", 10: "C126", 11: "C125", 12: "C127", 13: "C127", 14: "C125", 15: "C125",
                   16: "C125", 17: "C125"}

BANDS = {0: "", 1: "S", 2: "X", 3: "Ka", 4: "Ku", 5: "L"}


def _fields(spec: str, prefix: str = "", taken: set[str] | None = None) -> list[tuple[str, str]]:
    out = []
    for item in spec.split():
        name, code = item.split(":")
        name = prefix + name if (taken and name in taken) else name
        out.append((name, ">" + code if code[0] in "uif" else code))
    return out


@lru_cache(maxsize=None)
def dtype(format_code: int, n_obs: int = 0) -> np.dtype:
    """Packed big-endian dtype of one whole SFDU of ``format_code`` (``n_obs`` groups for 16/17)."""
    fields = _fields(HEADER)
    ddid = CLASS_OF_FORMAT[format_code]
    fields += [("sec_chdo_type", ">u2"), ("sec_chdo_length", ">u2")]
    taken = {n for n, _ in fields}
    fields += _fields(SECONDARY[ddid], "sec_", taken)
    taken = {n for n, _ in fields}
    fields += [("trk_chdo_type", ">u2"), ("trk_chdo_length", ">u2")]
    fields += _fields(TRACKING[format_code], "trk_", taken)
    if format_code in REPEATED:
        fields.append(("obs", np.dtype(_fields(REPEATED[format_code])), (n_obs,)))
        fields.append(("trailer_reserve8", "V8"))
    return np.dtype(fields)


@lru_cache(maxsize=None)
def secondary_bytes(ddid: str) -> int:
    """Length in bytes of the secondary CHDO value field plus its 4-byte CHDO header."""
    return 4 + np.dtype(_fields(SECONDARY[ddid])).itemsize


@lru_cache(maxsize=None)
def fixed_bytes(format_code: int) -> int:
    """SFDU length in bytes without repeated groups (and without the trailer for 16/17)."""
    return dtype(format_code, 0).itemsize - (TRAILER_BYTES if format_code in REPEATED else 0)


@lru_cache(maxsize=None)
def group_bytes(format_code: int) -> int:
    """Bytes per repeated observation group (0 for fixed-length formats)."""
    return np.dtype(_fields(REPEATED[format_code])).itemsize if format_code in REPEATED else 0
