/PROG  PICK_TWO_FRAMES
/ATTR
OWNER		= MNEDITOR;
COMMENT		= "pick st1 place st2";
PROG_SIZE	= 2310;
CREATE		= DATE 24-03-11  TIME 08:12:40;
MODIFIED	= DATE 24-03-12  TIME 14:02:16;
FILE_NAME	= ;
VERSION		= 0;
LINE_COUNT	= 15;
MEMORY_SIZE	= 2750;
PROTECT		= READ_WRITE;
TCD:  STACK_SIZE	= 0,
      TASK_PRIORITY	= 50,
      TIME_SLICE	= 0,
      BUSY_LAMP_OFF	= 0,
      ABORT_REQUEST	= 0,
      PAUSE_REQUEST	= 0;
DEFAULT_GROUP	= 1,*,*,*,*;
CONTROL_CODE	= 00000000 00000000;
/APPL
/MN
   1:  !pick at station 1, place at station 2 ;
   2:  UFRAME_NUM=1 ;
   3:  UTOOL_NUM=1 ;
   4:J P[1] 100% CNT100    ;
   5:L P[2] 500mm/sec FINE    ;
   6:  RO[1]=ON ;
   7:  WAIT   0.30(sec) ;
   8:L P[3] 1000mm/sec CNT50    ;
   9:  UFRAME_NUM=2 ;
  10:  UTOOL_NUM=2 ;
  11:J P[4] 100% CNT100    ;
  12:C P[5]    
    :  P[6] 300mm/sec CNT20    ;
  13:L P[7] 200mm/sec FINE    ;
  14:  RO[1]=OFF ;
  15:J P[4] 100% CNT100    ;
/POS
P[1]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   191.298  mm,	Y =   637.091  mm,	Z =  -997.595  mm,
	W =   -74.999 deg,	P =    -6.028 deg,	R =  -172.751 deg
};
P[2]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   227.483  mm,	Y =   377.893  mm,	Z = -1064.599  mm,
	W =   -76.838 deg,	P =    -8.756 deg,	R =  -173.654 deg
};
P[3]{
   GP1:
	UF : 1, UT : 1,		CONFIG : 'F U T, 0, 0, 0',
	X =   255.246  mm,	Y =   587.294  mm,	Z =  -895.234  mm,
	W =   -77.954 deg,	P =    -4.982 deg,	R =  -174.472 deg
};
P[4]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   107.795  mm,	Y =  -799.932  mm,	Z =   -21.709  mm,
	W =   115.839 deg,	P =     7.908 deg,	R =   172.078 deg
};
P[5]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   131.136  mm,	Y =  -858.732  mm,	Z =  -208.407  mm,
	W =   115.761 deg,	P =     7.457 deg,	R =   168.455 deg
};
P[6]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   127.294  mm,	Y =  -938.349  mm,	Z =  -223.496  mm,
	W =   114.206 deg,	P =     8.863 deg,	R =   166.412 deg
};
P[7]{
   GP1:
	UF : 2, UT : 2,		CONFIG : 'F U T, 0, 0, 0',
	X =   120.130  mm,	Y =  -986.796  mm,	Z =  -308.999  mm,
	W =   114.168 deg,	P =     8.370 deg,	R =   163.734 deg
};
/END
