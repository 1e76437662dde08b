!> The scene as written for any number of bodies (issue 19, "Mechanisms as data"): the
!> arrays of the chain shorthand (`m = 5*1.0`, `&link d_min = 4*0.25`), the repeatable
!> `&contact`, `&spring`, `&sine` and `&friction` records, and the field table that says which group each name
!> belongs to and which tutorial name is an alias of which element (m1 -> m(1), k12 ->
!> k_link(1)). The tutorial's n_real scalars stay in scene_input's slots; this is the rest.
module impact1d_fields
  use impact1d_kinds, only: wp
  use impact1d_forcing, only: table_type
  implicit none
  private
  public :: n_arrays, array_names, array_groups, array_aliases, array_is_link, array_is_text
  public :: a_m, a_mu, a_mus, a_x, a_v, a_f, a_f_amp, a_f_period, a_f_phase, a_k, a_x_rest, a_c
  public :: a_d_min, a_r_min, a_d_max, a_r_max, a_k_link, a_d_rest, a_c_link, a_f_table, a_belt_v, a_v_s, a_c_v
  public :: a_belt_amp, a_belt_period, a_belt_phase
  public :: n_contact_fields, contact_fields, n_spring_fields, spring_fields, n_sine_fields, sine_fields
  public :: r_a, r_b, r_d_min, r_r_min, r_d_max, r_r_max, r_name, r_k, r_d_rest, r_c, r_stop_k, r_stop_c
  public :: r_body, r_amp, r_period, r_phase, r_ground_v, r_spring_ground_v, n_ground_fields
  public :: r_ratio, r_spring_ratio
  public :: r_ground_table, r_spring_ground_table
  public :: n_friction_fields, friction_fields, r_mu, r_mus, r_normal, r_friction_name
  public :: name_len, text_item, written_array, record_input, chain_input, alias_name, mechanism_records, array_value

  !> Longest contact name a record may carry (names of events: '<name>', 'rest_<name>', ...).
  integer, parameter :: name_len = 32

  !> The arrays: body arrays hold N values (body i at i), link arrays N-1 (link i between
  !> bodies i and i+1). The alias is the tutorial's name of element i ('#' stands for i,
  !> i = 1, 2); one without '#' names element 1 only (the two-body link). The friction
  !> laws' arrays (belt_v, v_s, c_v: DESIGN "Laws added on the records"; belt_amp,
  !> belt_period, belt_phase, the belt's speed belt_v + belt_amp sin(2 pi t / belt_period +
  !> belt_phase): a design addition, named as the ground's motion is) have no tutorial
  !> name: they stay arrays for any N (impact1d_chain's fold keeps them).
  integer, parameter :: n_arrays = 26
  integer, parameter :: a_m = 1, a_mu = 2, a_mus = 3, a_x = 4, a_v = 5, a_f = 6, a_f_amp = 7, &
    a_f_period = 8, a_f_phase = 9, a_k = 10, a_x_rest = 11, a_c = 12, a_d_min = 13, a_r_min = 14, &
    a_d_max = 15, a_r_max = 16, a_k_link = 17, a_d_rest = 18, a_c_link = 19, a_f_table = 20, &
    a_belt_v = 21, a_v_s = 22, a_c_v = 23, a_belt_amp = 24, a_belt_period = 25, a_belt_phase = 26
  character(len=*), parameter :: array_names(n_arrays) = [character(len=11) :: &
    'm', 'mu', 'mus', 'x', 'v', 'f', 'f_amp', 'f_period', 'f_phase', 'k', 'x_rest', 'c', &
    'd_min', 'r_min', 'd_max', 'r_max', 'k_link', 'd_rest', 'c_link', 'f_table', 'belt_v', 'v_s', 'c_v', &
    'belt_amp', 'belt_period', 'belt_phase']
  character(len=*), parameter :: array_groups(n_arrays) = [character(len=7) :: &
    'bodies', 'bodies', 'bodies', 'initial', 'initial', 'forces', 'forces', 'forces', 'forces', &
    'springs', 'springs', 'springs', 'link', 'link', 'link', 'link', 'springs', 'springs', 'springs', &
    'forces', 'bodies', 'bodies', 'bodies', 'bodies', 'bodies', 'bodies']
  character(len=*), parameter :: array_aliases(n_arrays) = [character(len=9) :: &
    'm#', 'mu#', 'mus#', 'x#', 'v#', 'f#', 'f#_amp', 'f#_period', 'f#_phase', 'k#', 'x#_rest', 'c#', &
    'd_min', 'r_min', 'd_max', 'r_max', 'k12', 'd_rest', 'c12', 'f#_table', '', '', '', '', '', '']
  logical, parameter :: array_is_link(n_arrays) = [spread(.false., 1, 12), spread(.true., 1, 7), &
    spread(.false., 1, 7)]
  logical, parameter :: array_is_text(n_arrays) = [spread(.false., 1, 19), .true., spread(.false., 1, 6)]

  !> The fields of a &contact record (on x_b - x_a; a, b body numbers, 0 the ground; k and
  !> c make it a compliant stop: past a limit it pushes back with max(0, k p + c p')) and of
  !> a &spring record (tension k ((x_b - x_a) - d_rest) + c (v_b - v_a)). Either may move
  !> its ground end (a or b = 0): n_ground_fields from r_ground_v (contact) or
  !> r_spring_ground_v (spring): ground_v, ground_amp, ground_period, ground_phase, the
  !> prescribed motion w(t) = ground_v t + ground_amp sin(2 pi t / ground_period + ground_phase),
  !> and after them ground_table (r_ground_table, r_spring_ground_table: a text, the path of
  !> a (t, w) table added to w, read as a force table is).
  !> Either may carry a gear ratio n (r_ratio, r_spring_ratio; 1 when not given): it then
  !> acts on x_b - n x_a instead (docs/method.md section 14).
  integer, parameter :: n_ground_fields = 4
  integer, parameter :: n_contact_fields = 11 + n_ground_fields, n_spring_fields = 7 + n_ground_fields
  integer, parameter :: r_a = 1, r_b = 2, r_d_min = 3, r_r_min = 4, r_d_max = 5, r_r_max = 6, r_name = 7, &
    r_stop_k = 8, r_stop_c = 9, r_ground_v = 10, r_ground_table = 14, r_ratio = 15
  integer, parameter :: r_k = 3, r_d_rest = 4, r_c = 5, r_spring_ground_v = 6, r_spring_ground_table = 10, &
    r_spring_ratio = 11
  character(len=*), parameter :: contact_fields(n_contact_fields) = [character(len=13) :: &
    'a', 'b', 'd_min', 'r_min', 'd_max', 'r_max', 'name', 'k', 'c', 'ground_v', 'ground_amp', 'ground_period', &
    'ground_phase', 'ground_table', 'ratio']
  character(len=*), parameter :: spring_fields(n_spring_fields) = [character(len=13) :: &
    'a', 'b', 'k', 'd_rest', 'c', 'ground_v', 'ground_amp', 'ground_period', 'ground_phase', 'ground_table', 'ratio']
  !> The fields of a &sine record: amp sin(2 pi t / period + phase) on body `body`'s force
  !> (phase optional, 0 by default).
  integer, parameter :: n_sine_fields = 4
  integer, parameter :: r_body = 1, r_amp = 2, r_period = 3, r_phase = 4
  character(len=*), parameter :: sine_fields(n_sine_fields) = [character(len=6) :: &
    'body', 'amp', 'period', 'phase']
  !> The fields of a &friction record: a friction contact between bodies a and b (on the
  !> relative velocity v_b - v_a) under a given constant normal load `normal` (N), sliding
  !> bound mu normal, static bound mus normal; `name` names its stick_/slip_ events.
  integer, parameter :: n_friction_fields = 6
  integer, parameter :: r_mu = 3, r_mus = 4, r_normal = 5, r_friction_name = 6
  character(len=*), parameter :: friction_fields(n_friction_fields) = [character(len=6) :: &
    'a', 'b', 'mu', 'mus', 'normal', 'name']

  !> One text, kept whole (an array of these, not of deferred-length strings: see
  !> impact1d_scene's scene_text).
  type :: text_item
    character(len=:), allocatable :: s
  end type text_item

  !> An array as written: n values (0: not written), numbers in v or texts in t.
  type :: written_array
    integer :: n = 0
    real(wp), allocatable :: v(:)
    type(text_item), allocatable :: t(:)
  end type written_array

  !> One &contact, &spring or &sine record as written, with the line it starts on (for messages).
  type :: record_input
    real(wp) :: value(n_contact_fields) = 0.0_wp
    logical :: given(n_contact_fields) = .false.
    character(len=:), allocatable :: name
    character(len=:), allocatable :: table     !< ground_table's path (a &contact or &spring record)
    integer :: line = 0
  end type record_input

  !> What a scene writes beyond the tutorial's scalars. n_bodies is N when the scene is
  !> written as arrays of more than two bodies (the arrays are then kept here); 0 when its
  !> bodies are the tutorial's one or two (arrays of those fold into the scalars).
  type :: chain_input
    integer :: n_bodies = 0
    type(written_array) :: array(n_arrays)
    real(wp) :: r_meet = 1.0_wp          !< &link r_meet: restitution where neighbours meet
    logical :: has_r_meet = .false.
    type(record_input), allocatable :: contacts(:), springs(:), sines(:), frictions(:)
  end type chain_input

  !> Contacts and elements as records, in the layout of the model's (scene_type, stage 2;
  !> here, below impact1d_scene, so that build_scene can take them: impact1d_chain's
  !> input_records makes them):
  !> walls, links, then &contact records in file order; ground springs, link springs, then
  !> &spring records in file order; the &sine records in file order. An end 0 is the ground
  !> (always the first end, a).
  type :: mechanism_records
    integer :: n_contacts = 0
    integer, allocatable :: contact_body(:, :)           !< (2, nc) ends a, b; 0 = ground; acts on x_b - x_a
    logical, allocatable :: contact_has(:, :)            !< (2, nc) lower / upper limit present
    real(wp), allocatable :: contact_limit(:, :)         !< (2, nc) d_min, d_max on x_b - x_a (walls: positions)
    real(wp), allocatable :: contact_restitution(:, :)   !< (2, nc) r at the lower, upper limit
    character(len=name_len), allocatable :: contact_name(:)   !< (nc) 'left' 'right' 'slot' 'link3' ...
    !> (nc) a compliant stop's stiffness (N/m) and damping (N s/m); k = 0: a rigid contact
    real(wp), allocatable :: contact_k(:), contact_c(:)
    integer :: n_elements = 0
    integer, allocatable :: element_body(:, :)           !< (2, ne) ends; elongation (x_b - x_a) - rest
    real(wp), allocatable :: element_k(:), element_c(:), element_rest(:)   !< (ne)
    !> (n_ground_fields, nc), (n_ground_fields, ne): the ground end's prescribed motion
    !> (v, amp, period, phase; period 0: no sine) when the record names any (contact_moves,
    !> element_moves: (nc), (ne)), even all 0: a ground that moves at 0 m/s
    real(wp), allocatable :: contact_ground(:, :), element_ground(:, :)
    logical, allocatable :: contact_moves(:), element_moves(:)
    !> (nc), (ne) the gear ratio n of each record: it acts on x_b - n x_a (1: none)
    real(wp), allocatable :: contact_ratio(:), element_ratio(:)
    !> (nc), (ne) the ground end's table (ground_table): its path (unallocated: none), and the
    !> table itself once read (impact1d_io's prepare_scene: tables_read)
    type(text_item), allocatable :: contact_table_path(:), element_table_path(:)
    type(table_type), allocatable :: contact_table(:), element_table(:)
    logical :: tables_read = .false.
    integer :: n_sines = 0                               !< the &sine records, in file order
    integer, allocatable :: sine_body(:)                 !< (ns) the body whose force it adds to
    real(wp), allocatable :: sine_amp(:), sine_period(:), sine_phase(:)   !< (ns) N, s, rad
    integer :: n_frictions = 0                           !< the &friction records, in file order
    integer, allocatable :: friction_body(:, :)          !< (2, nf) ends a < b, bodies
    real(wp), allocatable :: friction_slide(:), friction_static(:)   !< (nf) mu normal, mus normal, N
    character(len=name_len), allocatable :: friction_name(:)   !< (nf) 'friction1' unless named
  end type mechanism_records

contains

  !> Element i of array j of a chain (N > 2: as written), or default when it is not written.
  pure real(wp) function array_value(chain, j, i, default)
    type(chain_input), intent(in) :: chain
    integer, intent(in) :: j, i
    real(wp), intent(in) :: default
    array_value = default
    if (chain%array(j)%n >= i) array_value = chain%array(j)%v(i)
  end function array_value

  !> The tutorial's name of element i of array j ('m2', 'k12'), or '' when it has none.
  pure function alias_name(j, i) result(name)
    integer, intent(in) :: j, i
    character(len=16) :: name     ! blank padded: callers trim
    integer :: hash
    name = ''
    hash = index(array_aliases(j), '#')
    if (hash == 0 .and. i == 1) name = array_aliases(j)
    if (hash > 0 .and. (i == 1 .or. i == 2)) name = array_aliases(j)(:hash - 1) // achar(iachar('0') + i) // &
      trim(array_aliases(j)(hash + 1:))
  end function alias_name
end module impact1d_fields
